#include "cartpole_qlearning/learning/experience_replay.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

using namespace cartpole_qlearning;

namespace
{
// Two rows a state, told apart by the transition's number k: rows 10k and 10k + 1, next 10k + 5, 10k + 6.
ActiveRows rowsOf(unsigned k, unsigned shift)
{
  ActiveRows rows;
  rows.rows[0] = 10 * k + shift;
  rows.rows[1] = 10 * k + shift + 1;
  rows.count = 2;
  return rows;
}

void addNumbered(ExperienceReplay& replay, unsigned k)
{
  replay.add(rowsOf(k, 0), k % 3, static_cast<double>(k), rowsOf(k, 5), k % 2 == 1);
}

// CartPole-v1 on bins, every step the same tilt: ends at the third state (theta beyond 12 degrees).
void runTiltingEpisodes(TrainingSession& session, unsigned episodes)
{
  for (unsigned i = 0; i < episodes; ++i)
  {
    session.beginEpisode(CartPoleState(0.0, 0.0, 0.01 * (i % 5), 0.0));
    for (double theta : {0.1, 0.15, 0.3})
      if (session.observe(CartPoleState(0.0, 0.1, theta, 1.0)).episode_over)
        break;
  }
}
}  // namespace

TEST(ExperienceReplay, KeepsTheLastCapacityTransitionsAndDrawsOnlyThemWhole)
{
  ExperienceReplay replay(3, 0);
  for (unsigned k = 0; k < 5; ++k)
    addNumbered(replay, k);
  EXPECT_EQ(3u, replay.size());
  std::set<unsigned> drawn;
  for (int i = 0; i < 200; ++i)
  {
    const ReplayedTransition& t = replay.draw();
    const auto k = static_cast<unsigned>(t.reward);
    drawn.insert(k);
    // The parts of one transition come back together.
    ASSERT_EQ(2u, t.state.count);
    EXPECT_EQ(10 * k, t.state.rows[0]);
    EXPECT_EQ(10 * k + 1, t.state.rows[1]);
    EXPECT_EQ(10 * k + 5, t.next_state.rows[0]);
    EXPECT_EQ(10 * k + 6, t.next_state.rows[1]);
    EXPECT_EQ(k % 3, t.action);
    EXPECT_EQ(k % 2 == 1, t.next_is_terminal);
  }
  // The two oldest were overwritten; the three kept are all drawn.
  EXPECT_EQ((std::set<unsigned>{2, 3, 4}), drawn);
}

TEST(ExperienceReplay, TheSameSeedDrawsTheSameTransitions)
{
  ExperienceReplay a(100, 7);
  ExperienceReplay b(100, 7);
  ExperienceReplay other(100, 8);
  for (unsigned k = 0; k < 50; ++k)
  {
    addNumbered(a, k);
    addNumbered(b, k);
    addNumbered(other, k);
  }
  int differ = 0;
  for (int i = 0; i < 50; ++i)
  {
    const double from_a = a.draw().reward;
    EXPECT_EQ(from_a, b.draw().reward);
    differ += from_a != other.draw().reward ? 1 : 0;
  }
  EXPECT_GT(differ, 0);
}

TEST(ExperienceReplay, RefusesAStateOfAnotherRowCountAndDrawingFromNothing)
{
  ExperienceReplay replay(10, 0);
  EXPECT_THROW(replay.draw(), std::logic_error);
  EXPECT_THROW(ExperienceReplay(0, 0), std::invalid_argument);
  addNumbered(replay, 0);
  EXPECT_THROW(replay.add(ActiveRows::single(1), 0, 0.0, ActiveRows::single(2), false), std::invalid_argument);
}

TEST(ExperienceReplay, ASessionLearnsMoreFromTheSameStepsAndCountsOnlyTheSteps)
{
  AgentParams plain;
  // A small rate: with the default's 1.0 an update lands on its target, and replaying the same
  // deterministic steps would land there again.
  plain.alpha.type = ScheduleType::Constant;
  plain.alpha.start = 0.1;
  plain.alpha.min = 0.1;
  AgentParams replaying = plain;
  replaying.replay_updates = 8;
  replaying.replay_alpha = 0.5;
  TrainingSession without(TaskParams(), plain, 3);
  TrainingSession with(TaskParams(), replaying, 3);
  runTiltingEpisodes(without, 20);
  runTiltingEpisodes(with, 20);
  // Replayed updates take no step: both tables count the same steps and episodes.
  EXPECT_EQ(without.table().steps, with.table().steps);
  EXPECT_EQ(without.table().episodes, with.table().episodes);
  EXPECT_NE(without.table().values(), with.table().values());
}

TEST(ExperienceReplay, NoReplayIsTheLearnerAsItWasAndBadSettingsAreRefused)
{
  AgentParams a;
  AgentParams b;
  b.replay_capacity = 5;  // unused while replay_updates is 0
  b.replay_alpha = 0.3;
  TrainingSession first(TaskParams(), a, 1);
  TrainingSession second(TaskParams(), b, 1);
  runTiltingEpisodes(first, 30);
  runTiltingEpisodes(second, 30);
  EXPECT_EQ(first.table().values(), second.table().values());

  AgentParams bad;
  bad.replay_updates = kMaxReplayUpdates + 1;
  EXPECT_NE(std::string::npos, bad.validate().find("replay_updates")) << bad.validate();
  bad = AgentParams();
  bad.replay_capacity = 0;
  EXPECT_NE(std::string::npos, bad.validate().find("replay_capacity")) << bad.validate();
  bad = AgentParams();
  bad.replay_alpha = 1.5;
  EXPECT_NE(std::string::npos, bad.validate().find("replay_alpha")) << bad.validate();
}
