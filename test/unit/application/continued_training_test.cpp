// Training that goes on from a table or a run folder: which seed it uses, whether anything is left
// to train, and what a finished run reports, read from the files as train_headless finds them.
#include "cartpole_qlearning/application/continued_training.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
class ContinuedTrainingTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("continued_training_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "runs" / "a");
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }

  static QTable table(std::uint64_t episodes, std::uint64_t steps)
  {
    QTable t(DiscretiserParams(), {-10.0, 10.0});
    t.episodes = episodes;
    t.steps = steps;
    return t;
  }
  void writeRecord(const RunRecord& record)
  {
    std::ofstream(dir_ / "runs" / "a" / kRunRecordFile) << formatRunRecord(record);
  }

  fs::path dir_;
};

TEST_F(ContinuedTrainingTest, FreshTrainingUsesTheGivenSeedElseZeroAndHasEverythingToTrain)
{
  const ContinuedTraining fresh;
  EXPECT_EQ(0u, fresh.seed(std::nullopt));
  EXPECT_EQ(7u, fresh.seed(7u));
  EXPECT_FALSE(fresh.nothingToTrain(1));
  EXPECT_FALSE(fresh.finished());
  EXPECT_FALSE(fresh.solved());
}

TEST_F(ContinuedTrainingTest, ALoadedTableAtOrPastMaxEpisodesHasNothingToTrain)
{
  const ContinuedTraining loaded = loadedTraining([] { return table(30, 4000); });
  EXPECT_EQ(30u, loaded.table_episodes);
  EXPECT_FALSE(loaded.nothingToTrain(31));
  EXPECT_TRUE(loaded.nothingToTrain(30));
  EXPECT_TRUE(loaded.nothingToTrain(29));
  EXPECT_EQ(0u, loaded.seed(std::nullopt));  // a table has no seed of its own
  // A table that cannot be read decides nothing: RunApplication says what is wrong with it.
  const ContinuedTraining unreadable =
      loadedTraining([this]() -> QTable { return loadQTableFile((dir_ / "missing.yaml").string()); });
  EXPECT_EQ(0u, unreadable.table_episodes);
  EXPECT_FALSE(unreadable.nothingToTrain(1));
}

TEST_F(ContinuedTrainingTest, AResumedRunTakesItsRecordsSeedUnlessAnotherIsGiven)
{
  RunRecord record;
  record.seed = 42;
  record.episodes = 20;
  writeRecord(record);
  saveQTableUnder(table(20, 900), dir_.string(), "runs/a/q_table.yaml");
  const ContinuedTraining resumed = resumedTraining(dir_.string(), "runs/a");
  ASSERT_TRUE(resumed.record.has_value());
  EXPECT_EQ(42u, resumed.seed(std::nullopt));
  EXPECT_EQ(3u, resumed.seed(3u));
  EXPECT_FALSE(resumed.finished());
}

TEST_F(ContinuedTrainingTest, AResumedRunCountsItsCheckpointTablesEpisodesNotItsRecords)
{
  // A kill between the two saves leaves the record a checkpoint behind: the table wins.
  RunRecord record;
  record.episodes = 20;
  writeRecord(record);
  saveQTableUnder(table(40, 5000), dir_.string(), "runs/a/q_table.yaml");
  const ContinuedTraining resumed = resumedTraining(dir_.string(), "runs/a");
  EXPECT_EQ(40u, resumed.table_episodes);
  EXPECT_TRUE(resumed.nothingToTrain(40));
  EXPECT_FALSE(resumed.nothingToTrain(41));
}

TEST_F(ContinuedTrainingTest, AFinishedRunReportsInsteadOfRefusing)
{
  RunRecord record;
  record.seed = 5;
  record.finished = "solved";
  writeRecord(record);
  saveQTableUnder(table(259, 61681), dir_.string(), "runs/a/q_table.yaml");
  const ContinuedTraining solved = resumedTraining(dir_.string(), "runs/a");
  EXPECT_TRUE(solved.finished());
  EXPECT_TRUE(solved.solved());
  EXPECT_EQ(0u, solved.table_episodes);
  EXPECT_FALSE(solved.nothingToTrain(1));
  record.finished = "max_episodes";
  writeRecord(record);
  const ContinuedTraining ran_out = resumedTraining(dir_.string(), "runs/a");
  EXPECT_TRUE(ran_out.finished());
  EXPECT_FALSE(ran_out.solved());
}

TEST_F(ContinuedTrainingTest, AFolderWithoutARecordStillCountsItsTable)
{
  saveQTableUnder(table(12, 300), dir_.string(), "runs/a/q_table.yaml");
  const ContinuedTraining resumed = resumedTraining(dir_.string(), "runs/a");
  EXPECT_FALSE(resumed.record.has_value());
  EXPECT_EQ(12u, resumed.table_episodes);
  EXPECT_EQ(0u, resumed.seed(std::nullopt));
  // Nothing there at all, or a folder outside the table folder: nothing decided.
  const ContinuedTraining nothing = resumedTraining(dir_.string(), "runs/none");
  EXPECT_FALSE(nothing.record.has_value());
  EXPECT_EQ(0u, nothing.table_episodes);
  const ContinuedTraining outside = resumedTraining((dir_ / "runs").string(), "../runs/a");
  EXPECT_EQ(0u, outside.table_episodes);
}

}  // namespace
