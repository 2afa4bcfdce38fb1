// The last word on a training's default table: when it must hold the run's table, and whether it
// does, read back from the file.
#include "cartpole_qlearning/application/final_table_check.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
TEST(FinalTableCheck, OnlyASolvedRunThatWasNotStoppedReplacesTheDefaultTable)
{
  EXPECT_TRUE(replacesDefaultTable(true, false, true));
  EXPECT_FALSE(replacesDefaultTable(false, false, true));  // unsolved: the default table stays
  EXPECT_FALSE(replacesDefaultTable(true, true, true));    // stopped: its save went to the run folder
  EXPECT_FALSE(replacesDefaultTable(true, false, false));  // --no-run-folder without --save: none
}

TEST(FinalTableCheck, TheFileMustHoldTheTablesCounts)
{
  const fs::path dir = fs::temp_directory_path() / ("final_table_check_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "q_table.yaml").string();
  QTable table(DiscretiserParams(), {-10.0, 10.0});
  table.episodes = 259;
  table.steps = 61681;
  EXPECT_FALSE(fileHoldsTable(path, table));  // not written
  saveQTableFile(table, path);
  EXPECT_TRUE(fileHoldsTable(path, table));
  QTable later = table;
  later.steps += 1;
  EXPECT_FALSE(fileHoldsTable(path, later));
  later = table;
  later.episodes += 1;
  EXPECT_FALSE(fileHoldsTable(path, later));
  std::ofstream(path) << "not a table\n";
  EXPECT_FALSE(fileHoldsTable(path, table));
  fs::remove_all(dir);
}

}  // namespace
