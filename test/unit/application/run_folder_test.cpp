// A run's folder: its record, its name, making it (now or at the first thing written), its
// checkpoints, and a session resumed from one: what a respawned controller relies on to go on
// where the run was (episode and step counters, schedules, the solved window).
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/application/run_folder.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>

#include <unistd.h>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

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

constexpr std::time_t kStartTime = 1790000000;
constexpr int kLauncher = 77;

class RunFolderTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("run_folder_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    settings_.q_table_dir = dir_.string();
    settings_.run_id = "run_a";
    tables_ = TableStore(dir_.string(), "q_table.yaml", AbsolutePaths::MustLieInTheFolder);
    config_.task.max_episode_steps = 5;
    config_.task.solved_window = 2;
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  RunFolder folder() const
  {
    return RunFolder(settings_, tables_, [] { return kStartTime; });
  }
  TrainingSession session() const
  {
    return TrainingSession(config_.task, config_.agent, 0);
  }
  // An episode that falls at once.
  static void fall(TrainingSession& session)
  {
    session.beginEpisode(CartPoleState::Zero());
    session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));
  }
  static std::string name()
  {
    return runFolderName(kStartTime, "/cartpole", 0);
  }
  RunRecord record(const std::string& folder) const
  {
    return parseRunRecord(test::fileText((dir_ / folder / kRunRecordFile).string()));
  }

  fs::path dir_;
  RunSettings settings_;
  TrainingConfig config_;
  TableStore tables_{"", "", AbsolutePaths::MustLieInTheFolder};
};

TEST_F(RunFolderTest, ANewRunMakesItsFolderAndRecordUnderANameNotTaken)
{
  TrainingSession learner = session();
  LogLines log;
  RunFolder first = folder();
  EXPECT_EQ(RunOpening::Fresh, first.open({}, kLauncher, learner, log));
  EXPECT_EQ(name(), first.name());
  EXPECT_FALSE(first.resumed());
  EXPECT_FALSE(first.isDeferred());
  ASSERT_EQ(1u, log.size());
  EXPECT_EQ("run " + name() + ": checkpoints go to " + (dir_ / name() / "q_table.yaml").string(), log[0].text);
  EXPECT_EQ("run_a", record(name()).run_id);
  EXPECT_EQ(localTimeText(kStartTime), record(name()).started);
  RunFolder second = folder();
  second.open({}, kLauncher, learner, log);
  EXPECT_EQ(name() + "_2", second.name());
  EXPECT_EQ(name() + "/episodes.csv", first.file(kRunEpisodesFile));
  // Without a run folder at all: nothing named, nothing made.
  settings_.run_folder = false;
  RunFolder none = folder();
  EXPECT_EQ(RunOpening::Fresh, none.open({}, kLauncher, learner, log));
  EXPECT_EQ("", none.name());
  EXPECT_EQ(2u, test::filesBelow(dir_).size());
}

TEST_F(RunFolderTest, ARunThatWritesNothingAlongTheWayMakesItsFolderWhenAskedAndSaysItsName)
{
  settings_.checkpoint_every = 0;
  settings_.save_on_shutdown = false;
  TrainingSession learner = session();
  LogLines log;
  fs::create_directories(dir_ / name());  // taken meanwhile
  RunFolder run = folder();
  run.open({}, kLauncher, learner, log);
  EXPECT_TRUE(run.isDeferred());
  EXPECT_FALSE(run.takeNewName().has_value());
  run.makeDeferred();
  EXPECT_FALSE(run.isDeferred());
  EXPECT_TRUE(fs::is_directory(dir_ / (name() + "_2")));
  EXPECT_EQ(std::optional<std::string>(name() + "_2"), run.takeNewName());
  EXPECT_FALSE(run.takeNewName().has_value());  // said once
}

TEST_F(RunFolderTest, ACheckpointSavesTheBestTableBeforeTheRecordThatNamesIt)
{
  TrainingSession learner = session();
  LogLines log;
  RunFolder run = folder();
  run.open({}, kLauncher, learner, log);
  fall(learner);
  fall(learner);
  std::string message;
  ASSERT_TRUE(run.checkpoint(learner, "", nullptr, message)) << message;
  EXPECT_EQ("saved 2 episodes, 2 steps of training to " + (dir_ / name() / "q_table.yaml").string(), message);
  EXPECT_EQ(2u, record(name()).episodes);
  EXPECT_EQ(0u, record(name()).best_episode);
  EXPECT_FALSE(fs::exists(dir_ / name() / kRunBestTableFile));

  BestTable best{learner.table(), SuiteResult{{CaseResult{"nominal", 4, 4, 3, 4, 0.0}}, 1, ""}, 2};
  fall(learner);
  ASSERT_TRUE(run.checkpoint(learner, "max_episodes", &best, message)) << message;
  const RunRecord written = record(name());
  EXPECT_EQ(3u, written.episodes);
  EXPECT_EQ("max_episodes", written.finished);
  EXPECT_EQ(2u, written.best_episode);
  EXPECT_EQ(3u, written.best_worst_balanced);
  EXPECT_EQ(best.result.summary(), written.best_robustness);
  EXPECT_EQ(2u, loadQTableFile((dir_ / name() / kRunBestTableFile).string()).episodes);
  EXPECT_EQ(2u, run.loadBestTable().episodes);
  EXPECT_EQ((dir_ / name() / kRunBestTableFile).string(), run.bestTablePath());

  // A best table that cannot be written: neither the table nor the record is.
  BestTable better{learner.table(), best.result, 3};
  fs::remove(dir_ / name() / kRunBestTableFile);
  fs::create_directories(dir_ / name() / kRunBestTableFile);
  fall(learner);
  EXPECT_FALSE(run.checkpoint(learner, "", &better, message));
  EXPECT_EQ(0u, message.rfind("nothing written: the best table: ", 0)) << message;
  EXPECT_EQ(3u, record(name()).episodes);
}

TEST_F(RunFolderTest, OnlyARespawnOfTheSameRunGoesOnFromItsCheckpoint)
{
  settings_.checkpoint_every = 1;
  TrainingSession learner = session();
  LogLines log;
  RunFolder run = folder();
  run.open({}, kLauncher, learner, log);
  fall(learner);
  std::string message;
  ASSERT_TRUE(run.checkpoint(learner, "", nullptr, message)) << message;
  const RunIdentity identity{"run_a", kLauncher, run.name()};

  TrainingSession respawned = session();
  RunFolder again = folder();
  log.clear();
  EXPECT_EQ(RunOpening::GoesOn, again.open(identity, kLauncher, respawned, log));
  EXPECT_TRUE(again.resumed());
  EXPECT_EQ(run.name(), again.name());
  EXPECT_EQ(1u, respawned.episodesEnded());
  EXPECT_EQ("restarted; run " + name() + " goes on from its checkpoint: episode 1, 1 steps", log.at(0).text);

  TrainingSession other = session();
  RunFolder another_launch = folder();
  EXPECT_EQ(RunOpening::Fresh, another_launch.open(identity, kLauncher + 1, other, log));
  EXPECT_EQ(name() + "_2", another_launch.name());
  EXPECT_EQ(0u, other.episodesEnded());
}

TEST_F(RunFolderTest, WithoutACheckpointARespawnStartsOverAndAResumeIsRefused)
{
  TrainingSession learner = session();
  LogLines log;
  RunFolder run = folder();
  run.open({}, kLauncher, learner, log);
  RunFolder respawn = folder();
  log.clear();
  EXPECT_EQ(RunOpening::StartedOver, respawn.open({"run_a", kLauncher, run.name()}, kLauncher, learner, log));
  EXPECT_TRUE(respawn.resumed());
  EXPECT_EQ(LogLine::Level::Warn, log.at(0).level);

  RunFolder resumed = folder();
  EXPECT_THROW(resumed.selectForResume("../elsewhere"), ConfigError);
  resumed.selectForResume(run.name());
  EXPECT_THROW(resumed.resume(learner, log), ConfigError);
}

TEST_F(RunFolderTest, ARunThatFinishedHasNothingLeftToDo)
{
  TrainingSession learner = session();
  LogLines log;
  RunFolder run = folder();
  run.open({}, kLauncher, learner, log);
  fall(learner);
  std::string message;
  ASSERT_TRUE(run.checkpoint(learner, "solved", nullptr, message)) << message;
  RunFolder resumed = folder();
  resumed.selectForResume((dir_ / run.name()).string());  // absolute, inside the table folder
  EXPECT_EQ(run.name(), resumed.name());
  TrainingSession again = session();
  log.clear();
  EXPECT_EQ(RunOpening::FinishedAlready, resumed.resume(again, log));
  ASSERT_EQ(1u, log.size());  // nothing said of going on from the checkpoint: it does not
  EXPECT_EQ("run " + name() + " has finished already (solved, episode 1, " +
                std::to_string(again.lastEpisode().total_steps) + " steps); nothing left to do",
            log.back().text);
}

}  // namespace
