// The table store: the path rule (relative under the table folder, "" the default table, an
// absolute path the user's file only when the store says so, a service's path always in the
// folder), saves and loads, and the services' answers.
#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>

#include <unistd.h>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
class TableStoreTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = fs::temp_directory_path() / ("table_store_test_" + std::to_string(::getpid()) + "_" + name);
    outside_ = fs::temp_directory_path() / ("table_store_test_outside_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::remove_all(outside_);
    fs::create_directories(dir_);
    fs::create_directories(outside_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
    fs::remove_all(outside_);
  }
  // A table with counts of its own, to tell it from another.
  static QTable table(std::uint64_t episodes)
  {
    QTable t(DiscretiserParams(), {-10.0, 10.0});
    t.episodes = episodes;
    t.steps = 10 * episodes;
    return t;
  }

  fs::path dir_;
  fs::path outside_;
};

TEST_F(TableStoreTest, RelativePathsLieInTheFolderAndNothingNamesTheDefaultTable)
{
  const TableStore tables(dir_.string(), "q_table.yaml", AbsolutePaths::MustLieInTheFolder);
  EXPECT_EQ((dir_ / "runs" / "a.yaml").string(), tables.resolve("runs/a.yaml"));
  EXPECT_EQ((dir_ / "q_table.yaml").string(), tables.resolve(""));
  tables.save(table(3), "runs/a.yaml");
  EXPECT_EQ(3u, loadQTableFile((dir_ / "runs" / "a.yaml").string()).episodes);
  EXPECT_EQ(3u, tables.load("runs/a.yaml").episodes);
  tables.save(table(4), "");
  EXPECT_EQ(4u, tables.load((dir_ / "q_table.yaml").string()).episodes);  // absolute, but inside
  EXPECT_THROW(tables.resolve("../a.yaml"), FileError);
  EXPECT_THROW(tables.save(table(1), "a/../../a.yaml"), FileError);
  EXPECT_FALSE(fs::exists(dir_.parent_path() / "a.yaml"));
  // Without a default table, nothing names no table.
  EXPECT_THROW(TableStore(dir_.string(), "", AbsolutePaths::MustLieInTheFolder).resolve(""), FileError);
}

TEST_F(TableStoreTest, AnAbsolutePathIsTheUsersFileOnlyWhenTheStoreSaysSo)
{
  const std::string mine = (outside_ / "mine.yaml").string();
  const TableStore node(dir_.string(), mine, AbsolutePaths::MustLieInTheFolder);
  EXPECT_THROW(node.resolve(""), FileError);
  EXPECT_THROW(node.save(table(1), mine), FileError);
  EXPECT_FALSE(fs::exists(mine));

  const TableStore command_line(dir_.string(), mine, AbsolutePaths::AreTheUsersFiles);
  EXPECT_EQ(mine, command_line.resolve(""));
  EXPECT_EQ(mine, command_line.resolve(mine));
  command_line.save(table(2), mine);
  EXPECT_EQ(2u, command_line.load("").episodes);
  // Relative paths stay under the folder.
  EXPECT_EQ((dir_ / "b.yaml").string(), command_line.resolve("b.yaml"));
  EXPECT_THROW(command_line.load("../b.yaml"), FileError);
}

TEST_F(TableStoreTest, AServicesPathStaysInTheFolderWhateverTheUserMay)
{
  const std::string mine = (outside_ / "mine.yaml").string();
  const TableStore tables(dir_.string(), mine, AbsolutePaths::AreTheUsersFiles);
  EXPECT_THROW(tables.resolveForService((outside_ / "other.yaml").string()), FileError);
  for (const std::string& path : {(outside_ / "other.yaml").string(), std::string("../other.yaml")})
  {
    const ServiceAnswer saved = tables.serveSave(table(1), path);
    EXPECT_FALSE(saved.success) << path;
    EXPECT_EQ(0u, saved.message.rfind("nothing written: ", 0)) << saved.message;
    ASSERT_EQ(1u, saved.log.size());
    EXPECT_EQ(LogLine::Level::Warn, saved.log[0].level);
    EXPECT_EQ("save_q_table: " + saved.message, saved.log[0].text);
  }
  EXPECT_FALSE(fs::exists(outside_ / "other.yaml"));
  EXPECT_FALSE(fs::exists(dir_.parent_path() / "other.yaml"));
  // "" is the default table, which the user named: there it may lie outside.
  EXPECT_EQ(mine, tables.resolveForService(""));
  const ServiceAnswer saved = tables.serveSave(table(5), "");
  EXPECT_TRUE(saved.success) << saved.message;
  EXPECT_EQ("saved 5 episodes, 50 steps of training to " + mine, saved.message);
  EXPECT_EQ(LogLine::Level::Info, saved.log.at(0).level);
  EXPECT_EQ(5u, loadQTableFile(mine).episodes);
}

TEST_F(TableStoreTest, ALoadReplacesTheTableInUseOnlyWhenItFits)
{
  const TableStore tables(dir_.string(), "q_table.yaml", AbsolutePaths::MustLieInTheFolder);
  tables.save(table(7), "seven.yaml");
  std::uint64_t replaced = 0;
  const auto fits = [&](QTable t) {
    replaced = t.episodes;
    return std::string();
  };
  const ServiceAnswer loaded = tables.serveLoad("seven.yaml", fits);
  EXPECT_TRUE(loaded.success) << loaded.message;
  EXPECT_EQ(7u, replaced);
  EXPECT_EQ("loaded " + (dir_ / "seven.yaml").string() + " (7 episodes, 70 steps of training)", loaded.message);
  ASSERT_EQ(1u, loaded.log.size());
  EXPECT_EQ("load_q_table: " + loaded.message, loaded.log[0].text);

  const ServiceAnswer mismatch = tables.serveLoad("seven.yaml", [](QTable) { return std::string("two actions"); });
  EXPECT_FALSE(mismatch.success);
  EXPECT_EQ("refused, the table in use is unchanged: " + (dir_ / "seven.yaml").string() +
                " does not fit this controller: two actions",
            mismatch.message);
  EXPECT_EQ(LogLine::Level::Warn, mismatch.log.at(0).level);

  // What cannot be read never reaches the table in use.
  replaced = 0;
  std::ofstream(dir_ / "cut.yaml") << formatQTable(table(2)).substr(0, 100);
  for (const std::string path : {"cut.yaml", "missing.yaml", "../seven.yaml"})
  {
    const ServiceAnswer refused = tables.serveLoad(path, fits);
    EXPECT_FALSE(refused.success) << path;
    EXPECT_EQ(0u, refused.message.rfind("refused, the table in use is unchanged: ", 0)) << refused.message;
  }
  EXPECT_EQ(0u, replaced);
}

TEST_F(TableStoreTest, AServiceLoadReadsTheFileApartFromPuttingItInUse)
{
  // A controller reads while it serves states and puts the table in use afterwards: the read
  // alone touches nothing, and a file over the bound is refused unread, saying its size.
  const TableStore tables(dir_.string(), "q_table.yaml", AbsolutePaths::MustLieInTheFolder);
  tables.save(table(7), "seven.yaml");
  TableRead read = tables.readForService("seven.yaml");
  ASSERT_TRUE(read.table.has_value()) << read.refusal.message;
  EXPECT_EQ(7u, read.table->episodes);
  EXPECT_EQ((dir_ / "seven.yaml").string(), read.resolved);
  std::uint64_t replaced = 0;
  const ServiceAnswer used = tables.useForService(std::move(read), [&](QTable t) {
    replaced = t.episodes;
    return std::string();
  });
  EXPECT_TRUE(used.success) << used.message;
  EXPECT_EQ(7u, replaced);

  const std::uint64_t size = fs::file_size(dir_ / "seven.yaml");
  TableRead too_large = tables.readForService("seven.yaml", size - 1);
  EXPECT_FALSE(too_large.table.has_value());
  EXPECT_NE(std::string::npos, too_large.refusal.message.find(std::to_string(size) + " bytes, more than"))
      << too_large.refusal.message;
  replaced = 0;
  const ServiceAnswer refused = tables.useForService(std::move(too_large), [&](QTable t) {
    replaced = t.episodes;
    return std::string();
  });
  EXPECT_FALSE(refused.success);
  EXPECT_EQ(0u, replaced);
  EXPECT_EQ(0u, refused.message.rfind("refused, the table in use is unchanged: ", 0)) << refused.message;
  ASSERT_EQ(1u, refused.log.size());
  EXPECT_EQ(LogLine::Level::Warn, refused.log[0].level);
}

}  // namespace
