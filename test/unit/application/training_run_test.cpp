// A run's record and a session resumed from a checkpoint: what a respawned controller relies
// on to go on where the run was (episode and step counters, schedules, the solved window).
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/application/training_run.h"

#include <gtest/gtest.h>

#include <limits>

using namespace cartpole_qlearning;

namespace
{
TEST(RunRecord, RoundTripsExactly)
{
  RunRecord record;
  record.run_id = "run_host_1234_5678";
  record.name_space = "/cartpole";
  record.seed = 3;
  record.started = "2026-11-22 14:03:05";
  record.episodes = 300;
  record.steps = 40000;
  record.recent_returns = {500.0, 12.0, 0.1 + 0.2, 475.5};
  record.finished = "suite_passed";
  record.robustness = "nominal 100/100, one_step_late 97/100: PASSED";
  const RunRecord back = parseRunRecord(formatRunRecord(record));
  EXPECT_EQ(record.run_id, back.run_id);
  EXPECT_EQ(record.name_space, back.name_space);
  EXPECT_EQ(record.seed, back.seed);
  EXPECT_EQ(record.started, back.started);
  EXPECT_EQ(record.episodes, back.episodes);
  EXPECT_EQ(record.steps, back.steps);
  EXPECT_EQ(record.recent_returns, back.recent_returns);
  EXPECT_EQ(record.finished, back.finished);
  EXPECT_EQ(record.robustness, back.robustness);
  // No best judged yet: none written, none read.
  EXPECT_EQ(std::string::npos, formatRunRecord(record).find("best"));
  EXPECT_EQ(0u, back.best_episode);
  record.best_episode = 70;
  record.best_worst_balanced = 93;
  record.best_robustness = "nominal 100/100, all_at_once 93/100: PASSED";
  const RunRecord with_best = parseRunRecord(formatRunRecord(record));
  EXPECT_EQ(70u, with_best.best_episode);
  EXPECT_EQ(93u, with_best.best_worst_balanced);
  EXPECT_EQ(record.best_robustness, with_best.best_robustness);
  EXPECT_NE(std::string::npos, formatRunRecord(record).find("table: best_q_table.yaml"));
}

TEST(RunRecord, BadRecordsAreRefusedWithTheReason)
{
  RunRecord record;
  const std::string good = formatRunRecord(record);
  const auto refusal = [](const std::string& text) {
    try
    {
      parseRunRecord(text);
    }
    catch (const FileError& e)
    {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(std::string::npos, refusal("").find("not a run record"));
  EXPECT_NE(std::string::npos, refusal("format: cartpole_qlearning/q_table\n").find("not a run record"));
  std::string other = good;
  other.replace(other.find("finished: \"\""), 12, "finished: \"maybe\"");
  EXPECT_NE(std::string::npos, refusal(other).find("finished is 'maybe'")) << refusal(other);
  EXPECT_NE(std::string::npos, refusal(good + "best: 3\n").find("best must be a map")) << refusal(good + "best: 3\n");
  std::string nan = good;
  nan.replace(nan.find("recent_returns: []"), 18, "recent_returns: [1, .nan]");
  EXPECT_NE(std::string::npos, refusal(nan).find("not finite")) << refusal(nan);
  std::string cut = good.substr(0, good.find("steps:"));
  EXPECT_NE(std::string::npos, refusal(cut).find("missing key 'steps'")) << refusal(cut);
  std::string negative = good;
  negative.replace(negative.find("seed: 0"), 7, "seed: -1");
  EXPECT_NE(std::string::npos, refusal(negative).find("not readable")) << refusal(negative);
}

TEST(RunRecord, FolderNamesSayWhenWhereAndWhichSeed)
{
  const std::time_t when = 1795000000;  // any moment: the name shows it in local time
  const std::string stamp = localTimeText(when);
  std::string expected_time = stamp;
  for (char& c : expected_time)
    c = c == ' ' ? '_' : c == ':' ? '-' : c;
  EXPECT_EQ("runs/" + expected_time + "_cartpole_seed7", runFolderName(when, "/cartpole", 7));
  EXPECT_EQ("runs/" + expected_time + "_a_b_seed0", runFolderName(when, "/a/b", 0));
  EXPECT_EQ("runs/" + expected_time + "_root_seed0", runFolderName(when, "/", 0));
}

TEST(TrainingSession, AResumedRunGoesOnWhereItsCheckpointWas)
{
  TrainingConfig config;
  config.limits.stop_when_solved = false;
  HeadlessTrainer original(config, 5);
  for (int i = 0; i < 120; ++i)
    original.runEpisode();
  // The checkpoint a controller writes: the table (with its counters) and the recent returns.
  const QTable checkpoint = original.session().table();
  const std::vector<double> returns = original.session().recentReturns();
  ASSERT_EQ(100u, returns.size());
  const EpisodeSummary at_checkpoint = original.session().lastEpisode();

  HeadlessTrainer resumed(config, 99);
  ASSERT_EQ("", resumed.session().resume(checkpoint, returns));
  EXPECT_EQ(120u, resumed.session().episodesEnded());
  EXPECT_DOUBLE_EQ(at_checkpoint.mean_return_window, resumed.session().lastEpisode().mean_return_window);
  const EpisodeSummary& next = resumed.runEpisode();
  EXPECT_EQ(121u, next.episode);
  EXPECT_EQ(at_checkpoint.total_steps + next.steps, next.total_steps);
  EXPECT_EQ(121u, resumed.session().table().episodes);
  EXPECT_EQ(checkpoint.steps + next.steps, resumed.session().table().steps);
  // The schedules at episode 120 (0-based), not at 0.
  EXPECT_DOUBLE_EQ(resumed.session().agent().epsilon(120), next.epsilon);
  EXPECT_LT(next.epsilon, 0.5);
  // The window: the checkpoint's last 99 returns and this episode's.
  double sum = next.episode_return;
  for (std::size_t i = 1; i < returns.size(); ++i)
    sum += returns[i];
  EXPECT_DOUBLE_EQ(sum / 100.0, next.mean_return_window);
}

TEST(TrainingSession, AResumeThatDoesNotFitChangesNothing)
{
  TrainingConfig config;
  HeadlessTrainer trainer(config, 1);
  trainer.runEpisode();
  const std::vector<double> before = trainer.session().table().values();
  DiscretiserParams other = config.agent.discretiser;
  other.bins[0] += 1;
  QTable wrong(other, config.agent.actions);
  wrong.episodes = 500;
  EXPECT_NE("", trainer.session().resume(wrong, {1.0, 2.0}));
  EXPECT_EQ(1u, trainer.session().episodesEnded());
  EXPECT_EQ(before, trainer.session().table().values());
}
}  // namespace
