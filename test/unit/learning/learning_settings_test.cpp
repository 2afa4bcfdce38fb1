#include "cartpole_qlearning/learning/learning_settings.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <gtest/gtest.h>

using namespace cartpole_qlearning;

namespace
{
// Runs one episode of a pole that falls at the first step; returns its summary.
const EpisodeSummary& fallOnce(TrainingSession& session)
{
  session.beginEpisode(CartPoleState::Zero());
  session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));
  return session.lastEpisode();
}

// A session whose table has seen `episodes` episodes already.
TrainingSession sessionAt(std::uint64_t episodes, bool learning = true)
{
  const AgentParams agent;
  TrainingSession session(TaskParams(), agent, 0, learning);
  QTable table(agent.discretiser, agent.actions);
  table.episodes = episodes;
  EXPECT_EQ("", session.replaceTable(table));
  return session;
}
}  // namespace

TEST(LearningSettings, StartAsTheConfigurationWithoutOverrides)
{
  AgentParams agent;
  agent.gamma = 0.9;
  agent.epsilon.start = 0.7;
  const TrainingSession session(TaskParams(), agent, 0);
  const LearningSettings& s = session.learningSettings();
  EXPECT_EQ(0.9, s.gamma);
  EXPECT_EQ(0.7, s.epsilon.start);
  EXPECT_FALSE(s.epsilon_override.has_value());
  EXPECT_FALSE(s.alpha_override.has_value());
}

TEST(LearningSettings, OverridesAndGammaApplyFromTheNextEpisode)
{
  TrainingSession session = sessionAt(10);
  const double scheduled_epsilon = fallOnce(session).epsilon;
  ASSERT_GT(scheduled_epsilon, 0.5);  // the log schedule at episode 10: still exploring

  LearningSettings s = session.learningSettings();
  s.epsilon_override = 0.0;
  s.alpha_override = 0.2;
  s.gamma = 0.95;
  ASSERT_EQ("", session.setLearning(s));
  const EpisodeSummary& after = fallOnce(session);
  EXPECT_EQ(0.0, after.epsilon);
  EXPECT_EQ(0.2, after.alpha);
  EXPECT_EQ(0.95, after.gamma);
  EXPECT_EQ(0.95, session.agent().params().gamma);
  EXPECT_EQ(0.2, session.learningSettings().alpha_override.value());
}

TEST(LearningSettings, BackToTheScheduleResumesAtTheCurrentEpisodeCount)
{
  TrainingSession session = sessionAt(200);
  LearningSettings s = session.learningSettings();
  s.epsilon_override = 0.0;
  ASSERT_EQ("", session.setLearning(s));
  EXPECT_EQ(0.0, fallOnce(session).epsilon);  // episode 200 ends: 201 seen

  s.epsilon_override.reset();
  s.epsilon.start = 0.5;  // a new schedule too: read at the count, not started over at 0
  ASSERT_EQ("", session.setLearning(s));
  const double expected = Schedule(s.epsilon).value(201);
  EXPECT_LT(expected, 0.5);
  EXPECT_DOUBLE_EQ(expected, fallOnce(session).epsilon);
}

TEST(LearningSettings, ABadValueChangesNothingAndNamesTheField)
{
  TrainingSession session = sessionAt(10);
  LearningSettings in_use = session.learningSettings();
  in_use.alpha_override = 0.3;
  ASSERT_EQ("", session.setLearning(in_use));

  LearningSettings bad = in_use;
  bad.gamma = 0.5;  // valid, but the whole change is refused with the bad field
  bad.epsilon.min = 0.8;
  bad.epsilon.start = 0.5;
  const std::string error = session.setLearning(bad);
  EXPECT_EQ(0u, error.find("epsilon/min = 0.8 is not allowed")) << error;

  EXPECT_EQ(in_use.gamma, session.agent().params().gamma);
  EXPECT_EQ(in_use.epsilon.start, session.learningSettings().epsilon.start);
  EXPECT_EQ(0.3, session.learningSettings().alpha_override.value());
  const EpisodeSummary& next = fallOnce(session);
  EXPECT_DOUBLE_EQ(session.agent().epsilon(10), next.epsilon);
  EXPECT_EQ(0.3, next.alpha);
  EXPECT_EQ(in_use.gamma, next.gamma);
}

TEST(LearningSettings, EachCheckNamesItsField)
{
  const LearningSettings good;
  ASSERT_EQ("", good.validate());
  const auto error = [&](auto change) {
    LearningSettings s = good;
    change(s);
    return s.validate();
  };
  EXPECT_EQ(0u, error([](LearningSettings& s) { s.gamma = 1.5; }).find("gamma = 1.5"));
  EXPECT_EQ(0u, error([](LearningSettings& s) { s.alpha.start = -0.1; }).find("alpha/start = -0.1"));
  EXPECT_EQ(0u, error([](LearningSettings& s) {
                  s.epsilon.type = ScheduleType::Exponential;
                  s.epsilon.decay_rate = 0.0;
                }).find("epsilon/decay_rate = 0"));
  EXPECT_EQ(0u, error([](LearningSettings& s) { s.epsilon_override = 1.5; }).find("epsilon_override = 1.5"));
  EXPECT_EQ(0u, error([](LearningSettings& s) { s.alpha_override = -0.5; }).find("alpha_override = -0.5"));
  // An overridden schedule is still checked: going back to it must find it valid.
  EXPECT_EQ(0u, error([](LearningSettings& s) {
                  s.alpha_override = 0.1;
                  s.alpha.log_divisor = 0.0;
                }).find("alpha/log_divisor = 0"));
}

TEST(LearningSettings, EvaluationStaysGreedyWhateverIsSet)
{
  TrainingSession session = sessionAt(0, false);
  LearningSettings s = session.learningSettings();
  s.epsilon_override = 1.0;
  s.alpha_override = 1.0;
  ASSERT_EQ("", session.setLearning(s));
  const EpisodeSummary& e = fallOnce(session);
  EXPECT_EQ(0.0, e.epsilon);
  EXPECT_EQ(0.0, e.alpha);
  EXPECT_EQ(0u, session.table().episodes);
}

TEST(QLearningAgent, SetLearningChangesTheDiscountOfTheNextUpdate)
{
  AgentParams params;
  QLearningAgent agent(params, 0);
  agent.table().at(1, 0) = 10.0;
  ASSERT_EQ("", agent.setLearning(0.5, params.epsilon, params.alpha));
  agent.update(0, 0, 1.0, 1, false, 1.0);
  EXPECT_DOUBLE_EQ(1.0 + 0.5 * 10.0, agent.table().at(0, 0));

  ScheduleParams bad = params.alpha;
  bad.min = 2.0;
  EXPECT_NE("", agent.setLearning(0.9, params.epsilon, bad));
  EXPECT_EQ(0.5, agent.params().gamma);
}

// What the controller announces: only the fields that changed, named as dynparam names them.
TEST(LearningSettings, ChangesAreSaidFieldByFieldAndNothingWhenNothingChanged)
{
  LearningSettings before = LearningSettings::of(AgentParams());
  EXPECT_EQ("", learningChangesText(before, before));
  LearningSettings after = before;
  after.epsilon_override = 0.0;
  after.gamma = 0.95;
  after.alpha.min = 0.2;
  EXPECT_EQ("epsilon_override none -> 0, gamma 0.99 -> 0.95, alpha_min 0.05 -> 0.2",
            learningChangesText(before, after));
  EXPECT_EQ("epsilon_override 0 -> none, gamma 0.95 -> 0.99, alpha_min 0.2 -> 0.05",
            learningChangesText(after, before));

  after.alpha.type = ScheduleType::Constant;
  after.alpha.start = 0.5;
  const std::string text = learningSettingsText(after);
  EXPECT_EQ(0u, text.find("epsilon 0 (override; schedule ")) << text;
  EXPECT_NE(std::string::npos, text.find(", alpha constant 0.5, gamma 0.95")) << text;
}

TEST(LearningSettings, LiveTuningSaysWhatAppliedWhatWasRefusedAndWhatARespawnFound)
{
  const LearningSettings in_use = LearningSettings::of(AgentParams());
  LearningSettings wanted = in_use;
  wanted.gamma = 0.95;
  const LogLines applied = liveTuningLog(in_use, wanted, "", false, true);
  ASSERT_EQ(applied.size(), 1u);
  EXPECT_EQ(applied[0].level, LogLine::Level::Info);
  EXPECT_EQ(applied[0].text,
            "live tuning: gamma 0.99 -> 0.95 (gamma from the next update, epsilon and alpha from "
            "the next episode)");
  const LogLines evaluating = liveTuningLog(in_use, wanted, "", false, false);
  ASSERT_EQ(evaluating.size(), 1u);
  EXPECT_NE(evaluating[0].text.find("evaluating, so none of it applies"), std::string::npos);
  const LogLines respawn = liveTuningLog(in_use, wanted, "", true, true);
  ASSERT_EQ(respawn.size(), 1u);
  EXPECT_EQ(respawn[0].level, LogLine::Level::Warn);
  EXPECT_EQ(respawn[0].text.find("restarted; the live tuning of this run before the restart applies again: gamma"), 0u);
  EXPECT_TRUE(liveTuningLog(in_use, in_use, "", false, true).empty());

  const LogLines refused = liveTuningLog(in_use, wanted, "epsilon_min = 0.9 is not allowed", false, true);
  ASSERT_EQ(refused.size(), 1u);
  EXPECT_EQ(refused[0].level, LogLine::Level::Warn);
  EXPECT_EQ(refused[0].text.find("live tuning refused (asked: gamma 0.99 -> 0.95): epsilon_min = 0.9 is not allowed; "
                                 "nothing changed, in use: "),
            0u)
      << refused[0].text;
  const LogLines refused_respawn = liveTuningLog(in_use, wanted, "epsilon_min = 0.9 is not allowed", true, true);
  EXPECT_EQ(refused_respawn[0].text.find("restarted; the live tuning left by the controller before the restart is "
                                         "refused (epsilon_min = 0.9 is not allowed): this run goes on with"),
            0u);

  EXPECT_TRUE(liveTuningReplacedLog(in_use, in_use).empty());
  const LogLines replaced = liveTuningReplacedLog(wanted, in_use);
  ASSERT_EQ(replaced.size(), 1u);
  EXPECT_EQ(replaced[0].text,
            "a new run: live-tuning values left on the parameter server replaced by its "
            "configuration's: gamma 0.95 -> 0.99");
}
