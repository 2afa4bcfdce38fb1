// The meters: steps per second (the learner's and each robot's) by the injected clock, the
// progress line at its cadence, the time since the start, and an evaluation's verdict.
#include "cartpole_qlearning/application/run_meters.h"

#include <gtest/gtest.h>

using namespace cartpole_qlearning;

namespace
{
class RunMetersTest : public ::testing::Test
{
protected:
  RunMeters meters()
  {
    return RunMeters(config_, settings_, [this] { return now_; });
  }
  static EpisodeSummary episode(std::uint64_t n, unsigned steps, std::uint64_t total_steps)
  {
    EpisodeSummary s;
    s.episode = n;
    s.steps = steps;
    s.total_steps = total_steps;
    s.episode_return = steps;
    return s;
  }

  TrainingConfig config_;
  RunSettings settings_;
  std::chrono::steady_clock::time_point now_{std::chrono::seconds(50)};
};

TEST_F(RunMetersTest, RatesAreTheLearnersSinceAnyEndAndEachRobotsSinceItsOwn)
{
  RunMeters m = meters();
  m.start(100);  // a table 100 steps into its training
  now_ += std::chrono::seconds(2);
  const RunMeters::Rates first = m.episodeEnded("robot_0", episode(1, 10, 110));
  EXPECT_DOUBLE_EQ(5.0, first.steps_per_second);
  EXPECT_DOUBLE_EQ(5.0, first.robot_steps_per_second);
  now_ += std::chrono::seconds(1);
  const RunMeters::Rates second = m.episodeEnded("robot_1", episode(2, 30, 140));
  EXPECT_DOUBLE_EQ(30.0, second.steps_per_second);
  EXPECT_DOUBLE_EQ(10.0, second.robot_steps_per_second);  // 30 steps in its 3 s
  EXPECT_DOUBLE_EQ(3.0, m.secondsRunning());
  // A loaded table: its steps count from now.
  m.countStepsFrom(1000);
  now_ += std::chrono::seconds(1);
  EXPECT_DOUBLE_EQ(10.0, m.episodeEnded("robot_0", episode(3, 10, 1010)).steps_per_second);
  // No time passed: no rate rather than a division by zero.
  EXPECT_DOUBLE_EQ(0.0, m.episodeEnded("robot_0", episode(4, 10, 1020)).steps_per_second);
}

TEST_F(RunMetersTest, ProgressComesAtItsCadenceWithTheRateSinceTheLastOne)
{
  config_.limits.progress_every = 2;
  RunMeters m = meters();
  m.start(0);
  LogLines log;
  now_ += std::chrono::seconds(1);
  const EpisodeSummary first = episode(1, 10, 10);
  m.episodeEnded("", first);
  m.addProgress(first, log);
  EXPECT_TRUE(log.empty());
  now_ += std::chrono::seconds(3);
  const EpisodeSummary second = episode(2, 30, 40);
  m.episodeEnded("", second);
  m.addProgress(second, log);
  ASSERT_EQ(1u, log.size());
  EXPECT_FALSE(log[0].prefixed);
  EXPECT_EQ(progressLine(second, config_.task.solved_window, 10.0, 4.0), log[0].text);
  config_.limits.progress_every = 0;
  RunMeters never = meters();
  never.start(0);
  never.episodeEnded("", second);
  never.addProgress(second, log);
  EXPECT_EQ(1u, log.size());
}

TEST_F(RunMetersTest, AnEvaluationSaysEachEpisodeAndItsVerdictAfterItsEpisodes)
{
  config_.task.max_episode_steps = 5;
  settings_.evaluation_episodes = 2;
  settings_.evaluation_case = "case pushes";
  settings_.evaluation_pass = 2;
  RunMeters m = meters();
  m.start(0);
  EpisodeSummary balanced = episode(1, 5, 5);
  balanced.truncated = true;
  balanced.mean_return_window = 5.0;
  LogLines log;
  EXPECT_FALSE(m.addEvaluationEpisode(balanced, log));
  EXPECT_EQ("evaluation episode 1: 5 steps, return 5.0, balanced to the step limit", log.at(0).text);
  EpisodeSummary fell = episode(2, 1, 6);
  fell.terminated = true;
  fell.mean_return_window = 3.0;
  EXPECT_TRUE(m.addEvaluationEpisode(fell, log));
  EXPECT_EQ("evaluation episode 2: 1 steps, return 1.0, fell", log.at(1).text);
  EXPECT_EQ(
      "EVALUATED 2 episodes: 1 balanced to the step limit (5 steps), mean return 3.0; case pushes: FAILED "
      "(needs 2)",
      log.at(2).text);
  TrainingSession session(config_.task, config_.agent, 0, false);
  EXPECT_EQ(0u, m.verdict(session).episodes);
  EXPECT_EQ(1u, m.verdict(session).balanced);
}

}  // namespace
