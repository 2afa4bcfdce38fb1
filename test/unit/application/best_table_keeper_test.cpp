// The best-table keeper: finding the suite, running it at its cadence, keeping the best table
// (a passing table beats a failing one, then the more balanced worst case, the first of equals),
// ending training on it, and a resumed run going on comparing against the best its folder holds.
#include "cartpole_qlearning/application/best_table_keeper.h"
#include "cartpole_qlearning/application/headless_trainer.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
class BestTableKeeperTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("best_table_keeper_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // Every episode due; a suite a trained table passes and a table of zeros fails.
    config_.limits.suite = (dir_ / "suite.yaml").string();
    config_.limits.suite_every = 1;
    std::ofstream(dir_ / "suite.yaml") << "episodes: 5\ncases: [{name: nominal, pass: 5}]\n";
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  // A table trained until solved (the default configuration, seed 0).
  static const QTable& trained()
  {
    static const QTable table = [] {
      HeadlessTrainer trainer(TrainingConfig(), 0);
      trainer.run();
      return trainer.session().table();
    }();
    return table;
  }
  // A learner holding `table` (its episode count is the session's).
  TrainingSession holding(const QTable& table) const
  {
    TrainingSession session(config_.task, config_.agent, 0);
    EXPECT_EQ("", session.resume(table, {}));
    return session;
  }
  static std::string all(const LogLines& log)
  {
    std::string text;
    for (const LogLine& line : log)
      text += line.text + "\n";
    return text;
  }

  fs::path dir_;
  TrainingConfig config_;
};

TEST_F(BestTableKeeperTest, TheSuiteIsFoundOrStopsOnlyARunThatNeedsIt)
{
  BestTableKeeper keeper(config_, true, {});
  EXPECT_NE(std::string::npos, all(keeper.loadSuite()).find("runs on the table after every episode; the best table"));
  EXPECT_TRUE(keeper.hasSuite());

  BestTableKeeper evaluating(config_, false, {});
  EXPECT_TRUE(evaluating.loadSuite().empty());
  EXPECT_FALSE(evaluating.hasSuite());

  config_.limits.suite = "suite.yaml";
  EXPECT_THROW(BestTableKeeper(config_, true, {"/nonexistent"}).loadSuite(), ConfigError);
  BestTableKeeper found(config_, true, {"/nonexistent", dir_.string()});
  found.loadSuite();
  EXPECT_TRUE(found.hasSuite());
  config_.limits.suite_every = 0;
  BestTableKeeper not_needed(config_, true, {"/nonexistent"});
  const LogLines log = not_needed.loadSuite();
  EXPECT_FALSE(not_needed.hasSuite());
  ASSERT_EQ(1u, log.size());
  EXPECT_EQ(LogLine::Level::Warn, log[0].level);
  EXPECT_NE(std::string::npos, log[0].text.find("without a robustness verdict")) << log[0].text;
}

TEST_F(BestTableKeeperTest, TheSuiteRunsAtItsCadenceAndWhenTrainingEnds)
{
  config_.limits.suite_every = 100;
  BestTableKeeper keeper(config_, true, {});
  keeper.loadSuite();
  QTable table = trained();
  table.episodes = 150;
  TrainingSession session = holding(table);
  LogLines log;
  EXPECT_FALSE(keeper.evaluateWhenDue(session, false, log).has_value());
  EXPECT_TRUE(log.empty());
  EXPECT_EQ(nullptr, keeper.best());
  const std::optional<SuiteResult> at_end = keeper.evaluateWhenDue(session, true, log);
  ASSERT_TRUE(at_end.has_value());
  EXPECT_TRUE(at_end->passed());
  ASSERT_EQ(1u, log.size());
  EXPECT_EQ(0u, log[0].text.rfind("robustness at episode 150 (", 0)) << log[0].text;
  ASSERT_NE(nullptr, keeper.best());
  EXPECT_EQ(150u, keeper.best()->episode);
}

TEST_F(BestTableKeeperTest, TrainingEndsOnTheBestTableSeenNotTheLast)
{
  BestTableKeeper keeper(config_, true, {});
  keeper.loadSuite();
  QTable good = trained();
  good.episodes = 10;
  TrainingSession session = holding(good);
  LogLines log;
  ASSERT_TRUE(keeper.evaluateWhenDue(session, false, log)->passed());
  // Worse later: a table of zeros, which falls.
  QTable zeros(config_.agent.discretiser, config_.agent.actions);
  zeros.episodes = 20;
  ASSERT_EQ("", session.resume(zeros, {}));
  const std::optional<SuiteResult> last = keeper.evaluateWhenDue(session, true, log);
  ASSERT_FALSE(last->passed());
  EXPECT_EQ(10u, keeper.best()->episode);
  log.clear();
  const SuiteResult saved = keeper.settle(session, last, log);
  EXPECT_TRUE(saved.passed());
  EXPECT_EQ(good.values(), session.table().values());
  EXPECT_NE(std::string::npos,
            all(log).find("keeping the table of episode 10 (worst case 5 balanced) over the last one (0)"))
      << all(log);
  // Trained until solved: the suite is information, and says where to go for a robust table.
  EXPECT_NE(std::string::npos, all(log).find("robustness of the saved table, for information (")) << all(log);
  EXPECT_NE(std::string::npos, all(log).find("every case passes: robust by this suite as well")) << all(log);

  // An equal later table does not replace the first.
  TrainingSession again = holding(good);
  BestTableKeeper first_of_equals(config_, true, {});
  first_of_equals.loadSuite();
  first_of_equals.evaluateWhenDue(again, false, log);
  QTable same = good;
  same.episodes = 30;
  ASSERT_EQ("", again.resume(same, {}));
  first_of_equals.evaluateWhenDue(again, false, log);
  EXPECT_EQ(10u, first_of_equals.best()->episode);
}

TEST_F(BestTableKeeperTest, TheTableKeptIsTheOneWholeVerdictsWouldKeepThoughMostAreCutShort)
{
  // Tables along three training runs, each judged by the keeper (against the best so far, cut
  // short when it cannot beat it) and, beside it, by whole verdicts with the same ranking: the
  // best table and the table saved at the end are the same after every one. Cases with different
  // pass counts, so that a failing best's worst case lies above some cases' pass.
  std::ofstream(dir_ / "suite.yaml") << "episodes: 20\ncases:\n"
                                        "  - {name: nominal, pass: 19}\n"
                                        "  - {name: wide, pass: 10, physics: {start_state_bound: 0.1}}\n"
                                        "  - {name: pushes, pass: 15, perturbations: {push_probability: 0.05, "
                                        "push_force: 2.0}}\n";
  const RobustnessSuite suite = loadRobustnessSuite((dir_ / "suite.yaml").string(), config_);
  const auto better = [](const SuiteResult& a, const SuiteResult& b) {
    return std::make_pair(a.passed(), a.worstBalanced()) > std::make_pair(b.passed(), b.worstBalanced());
  };
  std::size_t cut_short = 0;
  std::size_t judged = 0;
  for (std::uint64_t seed = 0; seed < 3; ++seed)
  {
    BestTableKeeper keeper(config_, true, {});
    keeper.loadSuite();
    std::optional<BestTable> reference;
    SuiteResult last_whole;
    std::optional<SuiteResult> last;
    TrainingSession session(config_.task, config_.agent, 0);
    for (std::uint64_t episodes = 10; episodes <= 400; episodes += 10)
    {
      TrainingConfig config = config_;
      config.limits.max_episodes = episodes;
      config.limits.suite = "none";
      HeadlessTrainer trainer(config, seed);
      trainer.run();
      ASSERT_EQ("", session.resume(trainer.session().table(), {}));
      LogLines log;
      last = keeper.evaluateWhenDue(session, false, log);
      ASSERT_TRUE(last.has_value());
      ++judged;
      cut_short += last->complete() ? 0 : 1;
      last_whole = evaluateSuite(session.table(), config_, suite);
      if (!reference || better(last_whole, reference->result))
        reference = BestTable{session.table(), last_whole, session.lastEpisode().episode};
      ASSERT_EQ(reference->episode, keeper.best()->episode) << "seed " << seed << ", episode " << episodes;
      EXPECT_EQ(reference->result.summary(), keeper.best()->result.summary());
      // A verdict cut short never says PASSED, nor FAILED of a table that passes.
      if (!last->complete())
      {
        EXPECT_TRUE(!last->passed() && (!last->failed() || !last_whole.passed())) << last->summary();
      }
    }
    // The end: the table saved is the best unless the last is better, on whole verdicts.
    LogLines log;
    const std::vector<double> expected =
        better(reference->result, last_whole) ? reference->table.values() : session.table().values();
    const SuiteResult saved = keeper.settle(session, last, log);
    EXPECT_EQ(expected, session.table().values()) << "seed " << seed;
    EXPECT_TRUE(saved.complete());
  }
  // The point of it: most verdicts needed only a part of the suite.
  EXPECT_GT(cut_short, judged / 2) << cut_short << " of " << judged << " cut short";
}

TEST_F(BestTableKeeperTest, WithoutTheSuiteDuringTrainingTheSavedTableIsEvaluatedAtTheEnd)
{
  config_.limits.suite_every = 0;
  BestTableKeeper keeper(config_, true, {});
  keeper.loadSuite();
  TrainingSession session = holding(trained());
  LogLines log;
  EXPECT_FALSE(keeper.evaluateWhenDue(session, true, log).has_value());
  EXPECT_EQ(nullptr, keeper.best());
  EXPECT_TRUE(keeper.settle(session, std::nullopt, log).passed());
  EXPECT_EQ(trained().values(), session.table().values());
}

TEST_F(BestTableKeeperTest, AResumedRunGoesOnComparingAgainstTheBestItsFolderHolds)
{
  RunSettings settings;
  settings.q_table_dir = dir_.string();
  const TableStore tables(dir_.string(), "q_table.yaml", AbsolutePaths::MustLieInTheFolder);
  const auto calendar = [] { return std::time_t(1790000000); };
  std::string name;
  {
    BestTableKeeper keeper(config_, true, {});
    keeper.loadSuite();
    QTable good = trained();
    good.episodes = 10;
    TrainingSession session = holding(good);
    RunFolder folder(settings, tables, calendar);
    LogLines log;
    folder.open({}, 0, session, log);
    keeper.evaluateWhenDue(session, false, log);
    std::string message;
    ASSERT_TRUE(folder.checkpoint(session, "", keeper.best(), message)) << message;
    name = folder.name();
  }
  TrainingSession session(config_.task, config_.agent, 0);
  RunFolder folder(settings, tables, calendar);
  LogLines log;
  folder.selectForResume(name);
  ASSERT_EQ(RunOpening::GoesOn, folder.resume(session, log));
  BestTableKeeper keeper(config_, true, {});
  keeper.loadSuite();
  const LogLines restored = keeper.restore(folder);
  EXPECT_NE(std::string::npos, all(restored).find("still the one to beat: episode 10, worst case 5 balanced"))
      << all(restored);
  ASSERT_NE(nullptr, keeper.best());
  EXPECT_EQ(10u, keeper.best()->episode);
  EXPECT_EQ(10u, folder.record().best_episode);

  // A best table that cannot be read is said, and forgotten.
  std::ofstream(dir_ / name / kRunBestTableFile) << "not a table";
  BestTableKeeper afresh(config_, true, {});
  afresh.loadSuite();
  const LogLines lost = afresh.restore(folder);
  ASSERT_EQ(1u, lost.size());
  EXPECT_EQ(LogLine::Level::Warn, lost[0].level);
  EXPECT_NE(std::string::npos, lost[0].text.find("the run's best table (episode 10) cannot be used")) << lost[0].text;
  EXPECT_EQ(nullptr, afresh.best());
  EXPECT_EQ(0u, folder.record().best_episode);
}

}  // namespace
