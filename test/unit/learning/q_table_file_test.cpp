#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <unistd.h>

using cartpole_qlearning::test::bitIdentical;
using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
class QTableFileTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("q_table_file_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }

  // A 72 x 2 table with values that are hard to print exactly.
  static QTable awkwardTable()
  {
    QTable table(DiscretiserParams(), {-10.0, 10.0});
    std::vector<double> values(table.values().size());
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = (i % 2 ? -1.0 : 1.0) / (3.0 + static_cast<double>(i)) * std::pow(10.0, static_cast<int>(i % 7) - 3);
    values[0] = std::numeric_limits<double>::denorm_min();
    values[1] = std::numeric_limits<double>::max();
    values[2] = -0.0;
    values[3] = 0.1 + 0.2;
    table.setValues(values);
    table.episodes = 1234;
    table.steps = 98765;
    return table;
  }

  std::string path(const std::string& name) const
  {
    return (dir_ / name).string();
  }

  static void write(const std::string& file, const std::string& text)
  {
    std::ofstream(file, std::ios::binary) << text;
  }

  // Loads into a training session's live table the way the controller does; returns the error.
  static std::string loadInto(TrainingSession& session, const std::string& file)
  {
    try
    {
      return session.replaceTable(loadQTableFile(file));
    }
    catch (const FileError& e)
    {
      return e.what();
    }
  }

  fs::path dir_;
};

}  // namespace

TEST_F(QTableFileTest, RoundTripIsBitExact)
{
  const QTable table = awkwardTable();
  saveQTableFile(table, path("table.yaml"));
  const QTable loaded = loadQTableFile(path("table.yaml"));
  EXPECT_TRUE(bitIdentical(table.values(), loaded.values()));
  EXPECT_TRUE(std::signbit(loaded.values()[2]));
  EXPECT_EQ("", table.shapeMismatch(loaded));
  EXPECT_EQ(1234u, loaded.episodes);
  EXPECT_EQ(98765u, loaded.steps);
  // Saving what was loaded gives the same bytes.
  saveQTableFile(loaded, path("again.yaml"));
  EXPECT_EQ(readFile(path("table.yaml")), readFile(path("again.yaml")));
}

TEST_F(QTableFileTest, FileDescribesItself)
{
  saveQTableFile(awkwardTable(), path("table.yaml"));
  const std::string text = readFile(path("table.yaml"));
  for (const char* key : {"format: cartpole_qlearning/q_table", "version: 2", "features: bins", "bins: [1, 1, 6, 12]",
                          "lower_bounds:", "upper_bounds:", "actions: [-10, 10]", "episodes: 1234", "steps: 98765",
                          "rows: 72", "checksum: fnv1a64:", "values:"})
    EXPECT_NE(std::string::npos, text.find(key)) << key;
}

TEST_F(QTableFileTest, SaveIsAtomicAndLeavesNoTemporaryFile)
{
  saveQTableFile(QTable(DiscretiserParams(), {-10.0, 10.0}), path("t.yaml"));
  saveQTableFile(awkwardTable(), path("t.yaml"));  // over an existing file
  EXPECT_TRUE(bitIdentical(awkwardTable().values(), loadQTableFile(path("t.yaml")).values()));
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_))
  {
    ++files;
    EXPECT_EQ("t.yaml", entry.path().filename().string());
  }
  EXPECT_EQ(1u, files);
}

TEST_F(QTableFileTest, SaveCreatesMissingDirectories)
{
  saveQTableFile(awkwardTable(), path("runs/seed0/q.yaml"));
  EXPECT_TRUE(fs::exists(path("runs/seed0/q.yaml")));
}

TEST_F(QTableFileTest, FailedSaveKeepsTheOldFile)
{
  saveQTableFile(awkwardTable(), path("t.yaml"));
  const std::string before = readFile(path("t.yaml"));
  write(path("blocker"), "a file, not a directory");
  EXPECT_THROW(saveQTableFile(awkwardTable(), path("blocker/t.yaml")), FileError);
  EXPECT_THROW(saveQTableFile(awkwardTable(), dir_.string()), FileError);
  EXPECT_EQ(before, readFile(path("t.yaml")));
}

TEST_F(QTableFileTest, TruncatedFilesAreRefusedAndTheLiveTableIsUntouched)
{
  TrainingSession session(TaskParams(), AgentParams(), 0);
  saveQTableFile(awkwardTable(), path("good.yaml"));
  ASSERT_EQ("", loadInto(session, path("good.yaml")));
  const std::vector<double> live = session.table().values();
  const std::string text = readFile(path("good.yaml"));
  // Cut at many places, on and off line boundaries, including inside the last number.
  for (std::size_t cut : {std::size_t(0), std::size_t(10), text.size() / 4, text.size() / 2, text.find("checksum"),
                          text.find("values:") + 9, text.size() - 40, text.size() - 3})
  {
    write(path("cut.yaml"), text.substr(0, cut));
    const std::string error = loadInto(session, path("cut.yaml"));
    EXPECT_FALSE(error.empty()) << "a file cut at " << cut << " of " << text.size() << " bytes was accepted";
    EXPECT_TRUE(bitIdentical(live, session.table().values()));
  }
}

TEST_F(QTableFileTest, CorruptValuesAreCaughtByTheChecksum)
{
  TrainingSession session(TaskParams(), AgentParams(), 0);
  const std::vector<double> live = session.table().values();
  saveQTableFile(awkwardTable(), path("t.yaml"));
  std::string text = readFile(path("t.yaml"));
  // Change one digit of one value: still valid YAML, still a number. (Row 3 holds ordinary
  // numbers; a digit deep in the denormal of row 0 would not change the double.)
  std::size_t row = text.find("values:");
  for (int i = 0; i <= 3; ++i)
    row = text.find("  - [", row + 1);
  const std::size_t digit = text.find_first_of("123456789", row + 8);
  text[digit] = text[digit] == '1' ? '2' : '1';
  write(path("t.yaml"), text);
  const std::string error = loadInto(session, path("t.yaml"));
  EXPECT_NE(std::string::npos, error.find("checksum")) << error;
  EXPECT_TRUE(bitIdentical(live, session.table().values()));
}

TEST_F(QTableFileTest, GarbageAndOtherYamlAreRefused)
{
  write(path("garbage.yaml"), std::string("\x01\x02\xff{{[[: :", 11));
  EXPECT_THROW(loadQTableFile(path("garbage.yaml")), FileError);
  write(path("other.yaml"), "physics:\n  gravity: 9.8\n");
  try
  {
    loadQTableFile(path("other.yaml"));
    FAIL() << "a config file was loaded as a Q-table";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("not a Q-table")) << e.what();
  }
}

// yaml-cpp before 0.7 (Debian 11, Noetic's Ubuntu 20.04) reads "-1" as the largest count.
TEST_F(QTableFileTest, ANegativeCountIsRefusedOnEveryYamlCpp)
{
  TrainingSession session(TaskParams(), AgentParams(), 0);
  const std::vector<double> live = session.table().values();
  saveQTableFile(awkwardTable(), path("t.yaml"));
  std::string text = readFile(path("t.yaml"));
  const std::size_t episodes = text.find("\nepisodes: ") + 1;
  ASSERT_NE(std::string::npos, episodes - 1);
  text.replace(episodes, text.find('\n', episodes) - episodes, "episodes: -1");
  write(path("t.yaml"), text);
  const std::string error = loadInto(session, path("t.yaml"));
  EXPECT_NE(std::string::npos, error.find("episodes is not a whole number >= 0")) << error;
  EXPECT_TRUE(bitIdentical(live, session.table().values()));
}

TEST_F(QTableFileTest, WrongVersionIsRefusedWithTheVersion)
{
  saveQTableFile(awkwardTable(), path("t.yaml"));
  std::string text = readFile(path("t.yaml"));
  text.replace(text.find("version: 2"), 10, "version: 4");
  write(path("t.yaml"), text);
  try
  {
    loadQTableFile(path("t.yaml"));
    FAIL() << "version 4 was accepted";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos,
              std::string(e.what()).find("version 4 is not supported (this build reads versions 1 to 3)"))
        << e.what();
  }
}

TEST_F(QTableFileTest, WrongShapeIsRefused)
{
  saveQTableFile(awkwardTable(), path("t.yaml"));
  std::string text = readFile(path("t.yaml"));
  std::string fewer_states = text;
  fewer_states.replace(fewer_states.find("rows: 72"), 8, "rows: 71");
  write(path("states.yaml"), fewer_states);
  EXPECT_THROW(loadQTableFile(path("states.yaml")), FileError);

  std::string short_row = text;
  const std::size_t row = short_row.find("  - [", short_row.find("values:"));
  short_row.replace(row, short_row.find('\n', row) - row, "  - [0.5]");
  write(path("row.yaml"), short_row);
  try
  {
    loadQTableFile(path("row.yaml"));
    FAIL() << "a row with one value was accepted";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("values row 0 has 1 entries, expected 2")) << e.what();
  }
}

TEST_F(QTableFileTest, AHeaderClaimingAHugeTableIsRefusedBeforeAnythingIsAllocated)
{
  // A few hundred bytes asking for 10^12 states: refused with a message, not std::bad_alloc.
  saveQTableFile(awkwardTable(), path("t.yaml"));
  std::string text = readFile(path("t.yaml"));
  const std::size_t bins = text.find("bins: [");
  text.replace(bins, text.find('\n', bins) - bins, "bins: [1000, 1000, 1000, 1000]");
  write(path("huge.yaml"), text);
  try
  {
    loadQTableFile(path("huge.yaml"));
    FAIL() << "a table of 10^12 states was accepted";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("1000000000000 states")) << e.what();
  }
  std::string wide = readFile(path("t.yaml"));
  const std::size_t b = wide.find("bins: [");
  wide.replace(b, wide.find('\n', b) - b, "bins: [10000000000, 1, 1, 1]");
  write(path("wide.yaml"), wide);
  EXPECT_THROW(loadQTableFile(path("wide.yaml")), FileError);
}

TEST_F(QTableFileTest, NoTableMayHoldMoreValuesThanTheLimit)
{
  // 5,000,000 states of 4 actions is the most; of 5 actions, one table too many.
  AgentParams agent;
  agent.discretiser.bins = {5, 100, 100, 100};
  agent.actions = {-10.0, -5.0, 5.0, 10.0};
  EXPECT_EQ("", agent.validate());
  agent.actions.push_back(0.0);
  EXPECT_NE(std::string::npos, agent.validate().find("more than the 20000000 values a table may hold"))
      << agent.validate();
  // A file claiming such a table is refused from its header.
  saveQTableFile(awkwardTable(), path("t.yaml"));
  std::string text = readFile(path("t.yaml"));
  const std::size_t bins = text.find("bins: [");
  text.replace(bins, text.find('\n', bins) - bins, "bins: [10, 100, 100, 100]");
  const std::size_t actions = text.find("actions: [");
  text.replace(actions, text.find('\n', actions) - actions, "actions: [-10, 0, 10]");
  write(path("wide.yaml"), text);
  try
  {
    loadQTableFile(path("wide.yaml"));
    FAIL() << "a table of 30,000,000 values was accepted";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("20000000 a table may hold")) << e.what();
  }
}

TEST_F(QTableFileTest, AFileLargerThanItsTableCouldBeIsRefusedUnread)
{
  // The bound for 72 rows of 2 values is about 1 MiB; a file of 3 MiB (a valid table padded
  // with a comment) is refused before reading, naming its size, and loads without the bound.
  saveQTableFile(awkwardTable(), path("t.yaml"));
  const std::uint64_t bound = maxQTableFileBytes(72, 2);
  EXPECT_GE(bound, readFile(path("t.yaml")).size());
  write(path("padded.yaml"), "# " + std::string(3u << 20, 'x') + "\n" + readFile(path("t.yaml")));
  try
  {
    loadQTableFile(path("padded.yaml"), bound);
    FAIL() << "a file of 3 MiB was read for a table of 72 rows";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos,
              std::string(e.what()).find(std::to_string((3u << 20) + 3 + readFile(path("t.yaml")).size()) + " bytes"))
        << e.what();
  }
  // Without a bound (a table given at start-up, whose shape nothing else tells) the file's own
  // first MiB must say what it is: here it is all comment.
  try
  {
    loadQTableFile(path("padded.yaml"));
    FAIL() << "a file of 3 MiB whose first MiB is no table header was read";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("no 'values:' line in its first 1048576 bytes"))
        << e.what();
  }
  // The bound holds for the longest values there are, in the widest table.
  QTable longest(DiscretiserParams(), std::vector<double>(kMaxActions, -1.0));
  longest.setValues(std::vector<double>(longest.values().size(), -std::numeric_limits<double>::min()));
  EXPECT_GE(maxQTableFileBytes(longest.stateCount(), kMaxActions), formatQTable(longest).size());
}

TEST_F(QTableFileTest, AFileLongerThanItsOwnHeaderClaimsIsRefusedAtTheCostOfItsHead)
{
  // A valid table followed by 5 MiB of rows its header does not count: with no bound given (the
  // node at start-up, train_headless --evaluate), the header's 72 rows of 2 values bound it.
  saveQTableFile(awkwardTable(), path("t.yaml"));
  const std::string table = readFile(path("t.yaml"));
  std::string rows;
  while (rows.size() < (5u << 20))
    rows += "  - [1.5, 2.5]\n";
  write(path("long.yaml"), table + rows);
  const std::string size = std::to_string(table.size() + rows.size());
  for (const bool under : {false, true})
  {
    try
    {
      under ? loadQTableUnder(dir_.string(), "long.yaml") : loadQTableFile(path("long.yaml"));
      FAIL() << "a file of 5 MiB was read for a table of 72 rows";
    }
    catch (const FileError& e)
    {
      EXPECT_NE(std::string::npos, std::string(e.what()).find("long.yaml: " + size +
                                                              " bytes, more than its own beginning says it can have (" +
                                                              std::to_string(maxQTableFileBytes(72, 2)) + ")"))
          << e.what();
    }
  }
  // A header that claims more than any table may hold is refused by the head alone too.
  std::string huge = table;
  const std::size_t at = huge.find("\nrows: 72\n");
  ASSERT_NE(std::string::npos, at);
  huge.replace(at, 10, "\nrows: 900000000\n");
  write(path("huge.yaml"), huge + rows);
  EXPECT_THROW(loadQTableFile(path("huge.yaml")), FileError);
  // A table within its bound still loads.
  EXPECT_TRUE(bitIdentical(awkwardTable().values(), loadQTableFile(path("t.yaml")).values()));
}

TEST_F(QTableFileTest, RowsLaidOutByHandLoadAsTheSameTable)
{
  // The rows as written are read straight from the text; any other YAML layout of them (block
  // lists, comments, other spacing) goes through yaml-cpp and gives the same table.
  const QTable table = awkwardTable();
  saveQTableFile(table, path("t.yaml"));
  const std::string text = readFile(path("t.yaml"));
  const std::size_t rows = text.find("values:\n") + 8;
  std::string by_hand = text.substr(0, rows) + "  # edited by hand\n";
  std::istringstream lines(text.substr(rows));
  for (std::string line; std::getline(lines, line);)
  {
    by_hand += "  -\n";
    std::istringstream values(line.substr(line.find('[') + 1, line.find(']') - line.find('[') - 1));
    for (std::string value; std::getline(values, value, ',');)
      by_hand += "    - " + value.substr(value.find_first_not_of(' ')) + "\n";
  }
  write(path("by_hand.yaml"), by_hand);
  const QTable loaded = loadQTableFile(path("by_hand.yaml"));
  EXPECT_TRUE(bitIdentical(table.values(), loaded.values()));
  EXPECT_EQ(table.episodes, loaded.episodes);
  // Rows of our layout that are too few are refused, counting them.
  write(path("short.yaml"), text.substr(0, text.rfind("  - [")));
  try
  {
    loadQTableFile(path("short.yaml"));
    FAIL() << "71 rows of 72 were accepted";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("values has 71 rows, expected 72")) << e.what();
  }
}

TEST_F(QTableFileTest, NumbersAreWrittenAsPrintfsShortestExactG)
{
  // 15 to 17 significant digits, %g's layout: what version 1 and 2 files always held.
  QTable table(DiscretiserParams(), {-10.0, 10.0});
  std::vector<double> values(table.values().size(), 0.0);
  const std::vector<std::pair<double, std::string>> expected = {{0.1, "0.1"},
                                                                {2.4, "2.4"},
                                                                {1e-05, "1e-05"},
                                                                {100000.0, "100000"},
                                                                {0.1 + 0.2, "0.30000000000000004"},
                                                                {1e20, "1e+20"},
                                                                {-0.0, "-0"},
                                                                {123456789012345678.0, "1.2345678901234568e+17"}};
  for (std::size_t i = 0; i < expected.size(); ++i)
    values[i] = expected[i].first;
  table.setValues(values);
  const std::string text = formatQTable(table);
  for (std::size_t i = 0; i + 1 < expected.size(); i += 2)
  {
    const std::string row = "  - [" + expected[i].second + ", " + expected[i + 1].second + "]\n";
    EXPECT_NE(std::string::npos, text.find(row)) << row;
  }
  EXPECT_TRUE(bitIdentical(values, parseQTable(text).values()));
}

TEST_F(QTableFileTest, ATableOfAnotherShapeIsRefusedByTheSessionAndTheLiveTableIsUntouched)
{
  TrainingSession session(TaskParams(), AgentParams(), 0);
  const std::vector<double> live = session.table().values();
  DiscretiserParams other;
  other.bins = {{1, 1, 3, 6}};
  saveQTableFile(QTable(other, {-10.0, 10.0}), path("other.yaml"));
  const std::string error = loadInto(session, path("other.yaml"));
  EXPECT_NE(std::string::npos, error.find("bins")) << error;
  saveQTableFile(QTable(DiscretiserParams(), {-10.0, 0.0, 10.0}), path("actions.yaml"));
  EXPECT_NE(std::string::npos, loadInto(session, path("actions.yaml")).find("actions"));
  EXPECT_TRUE(bitIdentical(live, session.table().values()));
}

TEST_F(QTableFileTest, MissingFileIsRefusedWithItsPath)
{
  try
  {
    loadQTableFile(path("nope.yaml"));
    FAIL();
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("nope.yaml")) << e.what();
  }
}

namespace
{
// A version 1 file as the build before tile coding wrote it (test/fuzz/corpus/q_table/tiny.yaml).
const char* const kVersion1Table =
    R"(# Q-table of cartpole_qlearning. The checksum covers every number below: edit by hand and the
# file will be refused.
format: cartpole_qlearning/q_table
version: 1
# Discretisation: uniform bins per state dimension; values outside the bounds go to the end bins.
dimensions: [x, x_dot, theta, theta_dot]
bins: [1, 1, 2, 2]
lower_bounds: [-2.4, -3, -0.20943951023931953, -0.8726646259971648]
upper_bounds: [2.4, 3, 0.20943951023931953, 0.8726646259971648]
# The effort [N] of each action: one column of values per action.
actions: [-10, 10]
# Training that produced this table.
episodes: 5
steps: 73
states: 4
checksum: fnv1a64:21088f60d2624369
# One row per state: the bins combined in mixed radix, x most significant.
values:
  - [16.54862385499124, 1]
  - [5.8519850599, 13.994164535871148]
  - [1, 0]
  - [1, 31.744540498961268]
)";

// 4 tilings of [1, 2, 6, 12] tiles with narrower x_dot bounds, 3 actions, awkward values.
QTable tilesTable()
{
  FeatureParams f;
  f.kind = FeatureKind::Tiles;
  f.tilings = 4;
  f.tiles = {{1, 2, 6, 12}};
  f.discretiser.lower[1] = -1.5;
  f.discretiser.upper[1] = 1.5;
  QTable table(f, {-10.0, 0.0, 10.0});
  std::vector<double> values(table.values().size());
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = 1.0 / (7.0 + static_cast<double>(i)) - 0.01 * static_cast<double>(i % 13);
  table.setValues(values);
  table.episodes = 42;
  table.steps = 4242;
  return table;
}
}  // namespace

TEST_F(QTableFileTest, ATileCodedTableRoundTripsAndSaysWhatItIs)
{
  const QTable table = tilesTable();
  ASSERT_EQ(4u * 3u * 7u * 13u, table.stateCount());
  saveQTableFile(table, path("tiles.yaml"));
  const std::string text = readFile(path("tiles.yaml"));
  for (const char* key : {"version: 2", "features: tiles", "tilings: 4", "tiles: [1, 2, 6, 12]",
                          "lower_bounds: [-2.4, -1.5,", "actions: [-10, 0, 10]", "rows: 1092"})
    EXPECT_NE(std::string::npos, text.find(key)) << key;
  EXPECT_EQ(std::string::npos, text.find("bins:"));
  const QTable loaded = loadQTableFile(path("tiles.yaml"));
  EXPECT_EQ(FeatureKind::Tiles, loaded.features().kind);
  EXPECT_EQ("", table.shapeMismatch(loaded));
  EXPECT_TRUE(bitIdentical(table.values(), loaded.values()));
  EXPECT_EQ(42u, loaded.episodes);
  saveQTableFile(loaded, path("again.yaml"));
  EXPECT_EQ(text, readFile(path("again.yaml")));

  // The checksum covers the tiling: a file that says 8 tilings over 4 tilings' rows is refused,
  // and so is one whose rows do not match its tilings.
  std::string tilings = text;
  tilings.replace(tilings.find("tilings: 4"), 10, "tilings: 2");
  tilings.replace(tilings.find("rows: 1092"), 10, "rows: 546");
  write(path("tilings.yaml"), tilings);
  EXPECT_THROW(loadQTableFile(path("tilings.yaml")), FileError);
  std::string huge = text;
  huge.replace(huge.find("tiles: [1, 2, 6, 12]"), 20, "tiles: [1000, 1000, 1000, 1000]");
  write(path("huge.yaml"), huge);
  try
  {
    loadQTableFile(path("huge.yaml"));
    FAIL() << "a header asking for 4 * 1001^4 tiles was accepted";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("more than the 10000000 allowed")) << e.what();
  }
}

TEST_F(QTableFileTest, AVersion1TableStillLoadsAsBins)
{
  write(path("v1.yaml"), kVersion1Table);
  const QTable table = loadQTableFile(path("v1.yaml"));
  EXPECT_EQ(FeatureKind::Bins, table.features().kind);
  EXPECT_EQ(4u, table.stateCount());
  EXPECT_EQ(31.744540498961268, table.at(3, 1));
  EXPECT_EQ(73u, table.steps);
  // Saved again it becomes version 2 with the same values and the same checksum.
  saveQTableFile(table, path("v2.yaml"));
  const std::string text = readFile(path("v2.yaml"));
  EXPECT_NE(std::string::npos, text.find("version: 2\n")) << text;
  EXPECT_NE(std::string::npos, text.find("checksum: fnv1a64:21088f60d2624369")) << text;
  EXPECT_TRUE(bitIdentical(table.values(), loadQTableFile(path("v2.yaml")).values()));
}

TEST_F(QTableFileTest, ATableOfOtherFeaturesIsRefusedSayingWhatDiffers)
{
  AgentParams bins;
  TrainingSession bins_session(TaskParams(), bins, 0);
  AgentParams tiles;
  tiles.features = FeatureKind::Tiles;
  tiles.tilings = 4;
  tiles.tiles = {{1, 2, 6, 12}};
  tiles.discretiser.lower[1] = -1.5;
  tiles.discretiser.upper[1] = 1.5;
  tiles.actions = {-10.0, 0.0, 10.0};
  TrainingSession tiles_session(TaskParams(), tiles, 0);
  const std::vector<double> bins_live = bins_session.table().values();
  const std::vector<double> tiles_live = tiles_session.table().values();

  saveQTableFile(tilesTable(), path("tiles.yaml"));
  EXPECT_EQ("features tiles differ from bins", loadInto(bins_session, path("tiles.yaml")));
  EXPECT_EQ("", loadInto(tiles_session, path("tiles.yaml")));
  tiles_session.replaceTable(QTable(tiles.featureParams(), tiles.actions));  // back to zeros
  saveQTableFile(awkwardTable(), path("bins.yaml"));
  EXPECT_EQ("features bins differ from tiles", loadInto(tiles_session, path("bins.yaml")));

  FeatureParams other = tilesTable().features();
  other.tilings = 8;
  saveQTableFile(QTable(other, tilesTable().actions()), path("tilings.yaml"));
  EXPECT_EQ("tilings 8 differ from 4", loadInto(tiles_session, path("tilings.yaml")));
  other = tilesTable().features();
  other.tiles = {{1, 2, 6, 10}};
  saveQTableFile(QTable(other, tilesTable().actions()), path("tiles10.yaml"));
  EXPECT_EQ("tiles [1, 2, 6, 10] differ from [1, 2, 6, 12]", loadInto(tiles_session, path("tiles10.yaml")));
  other = tilesTable().features();
  other.discretiser.upper[1] = 2.0;
  saveQTableFile(QTable(other, tilesTable().actions()), path("bounds.yaml"));
  const std::string bounds = loadInto(tiles_session, path("bounds.yaml"));
  EXPECT_EQ(0u, bounds.find("tile bounds lower [-2.3999999999999999, -1.5, ")) << bounds;
  EXPECT_NE(std::string::npos, bounds.find("upper [2.3999999999999999, 2, ")) << bounds;
  // The bins of a tiles table, and the bounds of an ignored dimension, play no part.
  other = tilesTable().features();
  other.discretiser.bins = {{3, 3, 3, 3}};
  other.discretiser.lower[0] = -1.0;
  saveQTableFile(QTable(other, {-10.0, 0.0, 10.0}), path("same.yaml"));
  EXPECT_EQ("", loadInto(tiles_session, path("same.yaml")));

  EXPECT_TRUE(bitIdentical(bins_live, bins_session.table().values()));
}

TEST_F(QTableFileTest, APreviousActionTableSaysSoAndAnOlderFileLoadsWithout)
{
  FeatureParams f;
  f.previous_action = true;
  QTable table(f, {-10.0, 10.0});
  ASSERT_EQ(72u * 3u, table.stateCount());  // none, after -10, after +10
  std::vector<double> values(table.values().size());
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = 1.0 / (1.0 + static_cast<double>(i));
  table.setValues(values);
  saveQTableFile(table, path("previous.yaml"));
  const std::string text = readFile(path("previous.yaml"));
  EXPECT_NE(std::string::npos, text.find("previous_action: true\n")) << text;
  EXPECT_NE(std::string::npos, text.find("rows: 216\n")) << text;
  const QTable loaded = loadQTableFile(path("previous.yaml"));
  EXPECT_TRUE(loaded.features().previous_action);
  EXPECT_TRUE(bitIdentical(table.values(), loaded.values()));

  // A table without it is written as it always was (no key, the same checksum), and reads back without it.
  saveQTableFile(awkwardTable(), path("plain.yaml"));
  EXPECT_EQ(std::string::npos, readFile(path("plain.yaml")).find("previous_action"));
  EXPECT_FALSE(loadQTableFile(path("plain.yaml")).features().previous_action);

  // The checksum covers it: the key taken away (rows made to fit) is refused.
  std::string stripped = text;
  stripped.replace(stripped.find("previous_action: true\n"), 22, "");
  write(path("stripped.yaml"), stripped);
  EXPECT_THROW(loadQTableFile(path("stripped.yaml")), FileError);
  std::string bad = text;
  bad.replace(bad.find("previous_action: true"), 21, "previous_action: yes!");
  write(path("bad.yaml"), bad);
  EXPECT_THROW(loadQTableFile(path("bad.yaml")), FileError);

  // A learner that sees the previous action takes no table that does not, and the other way round.
  AgentParams plain;
  TrainingSession plain_session(TaskParams(), plain, 0);
  EXPECT_EQ("previous_action true differs from false", loadInto(plain_session, path("previous.yaml")));
  AgentParams with;
  with.previous_action = true;
  TrainingSession with_session(TaskParams(), with, 0);
  EXPECT_EQ("previous_action false differs from true", loadInto(with_session, path("plain.yaml")));
  EXPECT_EQ("", loadInto(with_session, path("previous.yaml")));
}

TEST_F(QTableFileTest, ATableSaysTheStepItLearntAndTheConfigThatTrainedIt)
{
  QTable table = awkwardTable();
  table.tau = 0.04;
  table.trained_with = "/home/a user/configs/robust \"v2\": long.yaml";
  saveQTableFile(table, path("t.yaml"));
  const std::string text = readFile(path("t.yaml"));
  EXPECT_NE(std::string::npos, text.find("version: 3\n")) << text;
  EXPECT_NE(std::string::npos, text.find("tau: 0.04\n")) << text;
  const QTable back = loadQTableFile(path("t.yaml"));
  EXPECT_EQ(0.04, back.tau);
  EXPECT_EQ(table.trained_with, back.trained_with);
  EXPECT_TRUE(bitIdentical(table.values(), back.values()));
  // The checksum covers them: another step or config is a corrupt file.
  for (const auto& edit : {std::make_pair(std::string("tau: 0.04"), std::string("tau: 0.02")),
                           std::make_pair(std::string("long.yaml"), std::string("short.yaml"))})
  {
    std::string edited = text;
    edited.replace(edited.find(edit.first), edit.first.size(), edit.second);
    write(path("edited.yaml"), edited);
    EXPECT_THROW(loadQTableFile(path("edited.yaml")), FileError) << edit.second;
  }
  // Each alone is enough for version 3.
  QTable only_tau = awkwardTable();
  only_tau.tau = 0.02;
  saveQTableFile(only_tau, path("tau.yaml"));
  EXPECT_EQ(0.02, loadQTableFile(path("tau.yaml")).tau);
  EXPECT_EQ("", loadQTableFile(path("tau.yaml")).trained_with);
}

TEST_F(QTableFileTest, ATableThatKnowsNeitherIsTheVersion2FileItAlwaysWas)
{
  saveQTableFile(awkwardTable(), path("t.yaml"));
  const std::string text = readFile(path("t.yaml"));
  EXPECT_NE(std::string::npos, text.find("version: 2\n")) << text;
  EXPECT_EQ(std::string::npos, text.find("tau:")) << text;
  EXPECT_EQ(std::string::npos, text.find("trained_with:")) << text;
  EXPECT_EQ(0.0, loadQTableFile(path("t.yaml")).tau);
  // A version 3 file without either is refused: something was cut out of it.
  std::string v3 = text;
  v3.replace(v3.find("version: 2"), 10, "version: 3");
  write(path("v3.yaml"), v3);
  EXPECT_THROW(loadQTableFile(path("v3.yaml")), FileError);
}

TEST_F(QTableFileTest, TheConfigurationThatTrainedATableReadsAsTheConfigFileItIs)
{
  QTable table = awkwardTable();
  table.tau = 0.02;
  table.trained_with = trainingConfigText(TrainingConfig());
  saveQTableFile(table, path("t.yaml"));
  const std::string text = readFile(path("t.yaml"));
  // A literal block, one key a line, not one escaped line.
  EXPECT_NE(std::string::npos, text.find("trained_with: |")) << text;
  EXPECT_NE(std::string::npos, text.find("\n    tau: 0.02\n")) << text;
  EXPECT_EQ(table.trained_with, loadQTableFile(path("t.yaml")).trained_with);
  // Text a block cannot hold as it is (leading spaces, no final line break) is written quoted.
  table.trained_with = "  indented\n\n";
  saveQTableFile(table, path("odd.yaml"));
  EXPECT_EQ(table.trained_with, loadQTableFile(path("odd.yaml")).trained_with);
}

// train_headless --average: the mean of tables trained apart is one ordinary table.
namespace
{
QTable tableWith(double scale, std::uint64_t episodes)
{
  FeatureParams features;
  features.kind = FeatureKind::Tiles;
  features.tilings = 2;
  features.tiles = {2, 2, 3, 3};
  QTable table(features, {-10.0, 0.0, 10.0});
  std::vector<double> values(table.values().size());
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = scale * (static_cast<double>(i % 11) - 5.0) / 7.0;
  table.setValues(values);
  table.episodes = episodes;
  table.steps = 100 * episodes;
  table.tau = 0.02;
  table.trained_with = "learning:\n  features: tiles\n";
  return table;
}

// The mean of tables, added one at a time as train_headless --average reads them.
QTable meanOf(const std::vector<QTable>& tables)
{
  TableMean sum(tables.front());
  for (std::size_t i = 1; i < tables.size(); ++i)
    sum.add(tables[i]);
  return sum.mean();
}
}  // namespace

TEST(QTableMeanTest, EachValueIsTheMeanOfTheTablesAndTheCountersAreSummed)
{
  const std::vector<QTable> tables{tableWith(1.0, 3), tableWith(-0.5, 4), tableWith(0.3, 5)};
  const QTable mean = meanOf(tables);
  EXPECT_EQ("", tables[0].shapeMismatch(mean));
  ASSERT_EQ(tables[0].values().size(), mean.values().size());
  for (std::size_t i = 0; i < mean.values().size(); ++i)
    EXPECT_DOUBLE_EQ((tables[0].values()[i] + tables[1].values()[i] + tables[2].values()[i]) / 3.0, mean.values()[i])
        << "value " << i;
  EXPECT_EQ(12u, mean.episodes);
  EXPECT_EQ(1200u, mean.steps);
  EXPECT_EQ(0.02, mean.tau);
  EXPECT_EQ(tables[0].trained_with, mean.trained_with);
  // Its file is an ordinary table's: it loads as the same table.
  const std::string path =
      (fs::temp_directory_path() / ("q_table_mean_" + std::to_string(::getpid()) + ".yaml")).string();
  saveQTableFile(mean, path);
  const QTable loaded = loadQTableFile(path);
  fs::remove(path);
  EXPECT_TRUE(bitIdentical(mean.values(), loaded.values()));
  EXPECT_EQ(12u, loaded.episodes);
}

TEST(QTableMeanTest, SignsOfZeroSurviveAndASumPastTheLargestDoubleIsRefused)
{
  QTable a = tableWith(1.0, 1);
  QTable b = tableWith(1.0, 1);
  std::vector<double> values = a.values();
  values[0] = -0.0;
  values[1] = std::numeric_limits<double>::max();
  a.setValues(values);
  b.setValues(values);
  TableMean sum(a);
  EXPECT_EQ(1u, sum.count());
  EXPECT_TRUE(bitIdentical(a.values(), sum.mean().values()));  // one table: itself
  sum.add(b);
  EXPECT_EQ(2u, sum.count());
  try
  {
    sum.mean();
    ADD_FAILURE() << "a sum past the largest double was averaged";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_STREQ("a value's sum over the tables is not finite (values near the largest double)", e.what());
  }
  values[1] = 1.0;
  a.setValues(values);
  TableMean zeros(a);
  zeros.add(a);
  EXPECT_TRUE(std::signbit(zeros.mean().values()[0]));
}

TEST(QTableMeanTest, TablesThatLearntDifferentThingsAreRefusedSayingWhatDiffersAndAddNothing)
{
  TableMean sum(tableWith(1.0, 1));
  const auto refusal = [&sum](const QTable& table) {
    try
    {
      sum.add(table);
    }
    catch (const std::invalid_argument& e)
    {
      return std::string(e.what());
    }
    return std::string("no refusal");
  };
  QTable other_actions(tableWith(1.0, 1).features(), {-10.0, 10.0});
  EXPECT_EQ("actions [-10, 10] differ from [-10, 0, 10]", refusal(other_actions));
  FeatureParams bins;
  EXPECT_EQ(tableWith(1.0, 1).shapeMismatch(QTable(bins, {-10.0, 0.0, 10.0})),
            refusal(QTable(bins, {-10.0, 0.0, 10.0})));
  EXPECT_NE("", refusal(QTable(bins, {-10.0, 0.0, 10.0})));
  QTable other_tau = tableWith(1.0, 1);
  other_tau.tau = 0.01;
  EXPECT_EQ("its step (tau) 0.01 s differs from the first table's 0.02 s", refusal(other_tau));
  QTable other_config = tableWith(1.0, 1);
  other_config.trained_with = "learning:\n  features: bins\n";
  EXPECT_EQ(
      "the configuration that trained it (trained_with) differs from the first table's at line 2 '  features: bins' "
      "where the first's is '  features: tiles'",
      refusal(other_config));
  other_config.trained_with = tableWith(1.0, 1).trained_with + "  ensemble: 2\n";
  EXPECT_EQ(
      "the configuration that trained it (trained_with) differs from the first table's at line 3 '  ensemble: 2' "
      "where the first's is '(none)'",
      refusal(other_config));
  // Nothing refused was added: the mean is still the first table.
  EXPECT_EQ(1u, sum.count());
  EXPECT_TRUE(bitIdentical(tableWith(1.0, 1).values(), sum.mean().values()));
  EXPECT_EQ(1u, sum.mean().episodes);
}
