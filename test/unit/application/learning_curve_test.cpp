// The learning curve's file: a header and one row per episode, each row in the file as soon as
// it is written; a resumed run keeps the rows its checkpoint covers and never repeats the header
// or an episode; a file that is not a curve, or cannot be opened, is refused and left alone. And
// a run's curve: where it goes, when it opens.
#include "cartpole_qlearning/application/learning_curve.h"
#include "cartpole_qlearning/node_settings/node_setting_names.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
class LearningCurveFileTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("learning_curve_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  std::string text(const std::string& name) const
  {
    std::ifstream in(dir_ / name, std::ios::binary);
    std::ostringstream out;
    out << in.rdbuf();
    return out.str();
  }
  std::vector<std::string> lines(const std::string& name) const
  {
    std::vector<std::string> found;
    std::istringstream in(text(name));
    for (std::string line; std::getline(in, line);)
      found.push_back(line);
    return found;
  }
  static EpisodeSummary episode(std::uint64_t n)
  {
    EpisodeSummary s;
    s.episode = n;
    s.steps = static_cast<unsigned>(10 + n);
    s.episode_return = static_cast<double>(s.steps);
    s.mean_return_window = 0.1 * static_cast<double>(n);
    s.epsilon = 1.0 / 3.0;
    s.alpha = 0.5;
    s.gamma = 0.99;
    s.terminated = true;
    s.total_steps = 100 * n;
    return s;
  }
  fs::path dir_;
};
}  // namespace

TEST_F(LearningCurveFileTest, AHeaderThenOneRowPerEpisodeEachInTheFileAsSoonAsWritten)
{
  LearningCurveFile csv(AppendingFile::openUnder(dir_.string(), "runs/a/episodes.csv"));
  EXPECT_EQ(std::vector<std::string>{kLearningCurveHeader}, lines("runs/a/episodes.csv"));
  for (std::uint64_t n = 1; n <= 3; ++n)
  {
    csv.write(episode(n), "", 1700000000.25);
    // Read while the writer is still open: a live reader sees every ended episode.
    ASSERT_EQ(n + 1, lines("runs/a/episodes.csv").size());
  }
  EXPECT_EQ("2,,12,12,0.2,0.3333333333333333,0.5,true,false,false,200,1700000000.250,0.99",
            lines("runs/a/episodes.csv")[2]);
}

TEST_F(LearningCurveFileTest, NumbersReadBackAsTheSameDoubles)
{
  EpisodeSummary s = episode(7);
  s.mean_return_window = 475.00000000000006;
  s.epsilon = 0.1;
  const std::string row = learningCurveRow(s, "robot_1", 0.0);
  std::istringstream in(row);
  std::vector<std::string> fields;
  for (std::string f; std::getline(in, f, ',');)
    fields.push_back(f);
  ASSERT_EQ(13u, fields.size()) << row;
  EXPECT_EQ("robot_1", fields[1]);
  EXPECT_EQ(s.mean_return_window, std::stod(fields[4]));
  EXPECT_EQ(s.epsilon, std::stod(fields[5]));
  EXPECT_EQ(s.gamma, std::stod(fields[12]));  // live tuning may change it: the curve shows when
}

TEST_F(LearningCurveFileTest, ANewCurveReplacesWhatTheFileHeld)
{
  {
    LearningCurveFile csv(AppendingFile::openUnder(dir_.string(), "e.csv"));
    csv.write(episode(1), "", 0.0);
    csv.write(episode(2), "", 0.0);
  }
  LearningCurveFile csv(AppendingFile::openUnder(dir_.string(), "e.csv"));
  csv.write(episode(1), "", 0.0);
  EXPECT_EQ(2u, lines("e.csv").size());
}

TEST_F(LearningCurveFileTest, AResumedRunKeepsTheCheckpointsRowsWithoutASecondHeader)
{
  {
    LearningCurveFile csv(AppendingFile::openUnder(dir_.string(), "e.csv"));
    for (std::uint64_t n = 1; n <= 5; ++n)
      csv.write(episode(n), "", 0.0);
  }
  // Killed mid-row after episode 5; the checkpoint was at episode 3: the run plays 4 and 5 again.
  std::ofstream(dir_ / "e.csv", std::ios::app) << "6,,16,1";
  {
    LearningCurveFile csv(AppendingFile::openUnder(dir_.string(), "e.csv"), 3);
    EXPECT_EQ(4u, lines("e.csv").size());
    csv.write(episode(4), "", 0.0);
  }
  const std::vector<std::string> rows = lines("e.csv");
  ASSERT_EQ(5u, rows.size());
  EXPECT_EQ(kLearningCurveHeader, rows[0]);
  for (std::size_t i = 1; i < rows.size(); ++i)
    EXPECT_EQ(std::to_string(i) + ",", rows[i].substr(0, std::to_string(i).size() + 1));

  // A run that had no checkpoint starts over: the header alone stays.
  LearningCurveFile(AppendingFile::openUnder(dir_.string(), "e.csv"), 0);
  EXPECT_EQ(std::vector<std::string>{kLearningCurveHeader}, lines("e.csv"));
  // A missing or empty file gets the header once.
  LearningCurveFile(AppendingFile::openUnder(dir_.string(), "new.csv"), 40);
  LearningCurveFile(AppendingFile::openUnder(dir_.string(), "new.csv"), 40);
  EXPECT_EQ(std::vector<std::string>{kLearningCurveHeader}, lines("new.csv"));
}

TEST_F(LearningCurveFileTest, StartingOverLeavesTheHeaderAloneAndANumberingOfItsOwn)
{
  LearningCurveFile csv(AppendingFile::openUnder(dir_.string(), "e.csv"));
  for (std::uint64_t n = 1; n <= 5; ++n)
    csv.write(episode(n), "", 0.0);
  // A table of 300 episodes loaded: its episodes 301, 302 follow the header, nothing of before.
  csv.startOver();
  csv.write(episode(301), "", 0.0);
  csv.write(episode(302), "", 0.0);
  const std::vector<std::string> rows = lines("e.csv");
  ASSERT_EQ(3u, rows.size());
  EXPECT_EQ(kLearningCurveHeader, rows[0]);
  EXPECT_EQ("301,", rows[1].substr(0, 4));
  EXPECT_EQ("302,", rows[2].substr(0, 4));
}

TEST_F(LearningCurveFileTest, AFileThatIsNotACurveIsRefusedAndLeftAsItWas)
{
  std::ofstream(dir_ / "notes.csv") << "name,score\nada,3\n";
  EXPECT_THROW(LearningCurveFile(AppendingFile::openUnder(dir_.string(), "notes.csv"), 10), FileError);
  EXPECT_EQ("name,score\nada,3\n", text("notes.csv"));
  // A new run pointed at it by mistake (a Q-table's name, say) refuses it too, rather than empty it.
  EXPECT_THROW(LearningCurveFile(AppendingFile::openUnder(dir_.string(), "notes.csv")), FileError);
  EXPECT_EQ("name,score\nada,3\n", text("notes.csv"));
}

TEST_F(LearningCurveFileTest, APathThatCannotBeOpenedSaysWhy)
{
  fs::create_directories(dir_ / "folder.csv");
  try
  {
    AppendingFile::openUnder(dir_.string(), "folder.csv");
    FAIL() << "a directory was opened as a file";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("folder.csv")) << e.what();
  }
  fs::create_symlink(dir_ / "elsewhere.csv", dir_ / "link.csv");
  EXPECT_THROW(AppendingFile::openUnder(dir_.string(), "link.csv"), FileError);
  EXPECT_FALSE(fs::exists(dir_ / "elsewhere.csv"));
  EXPECT_THROW(AppendingFile::openUnder(dir_.string(), "../out.csv"), FileError);
  if (::geteuid() != 0)
  {
    fs::create_directories(dir_ / "locked");
    ::chmod((dir_ / "locked").c_str(), 0500);
    EXPECT_THROW(AppendingFile::open((dir_ / "locked" / "e.csv").string()), FileError);
    ::chmod((dir_ / "locked").c_str(), 0700);
  }
  // A path of the user's own follows links and makes its folders.
  AppendingFile::open((dir_ / "link.csv").string()).append("x");
  EXPECT_EQ("x", text("elsewhere.csv"));
  AppendingFile::open((dir_ / "made" / "e.csv").string());
  EXPECT_TRUE(fs::exists(dir_ / "made" / "e.csv"));
}

namespace
{
// A run's curve: where ~stats_csv puts it, when it opens, and a loaded table's new numbering.
class LearningCurveTest : public LearningCurveFileTest
{
protected:
  void SetUp() override
  {
    LearningCurveFileTest::SetUp();
    settings_.q_table_dir = dir_.string();
    settings_.names = nodeSettingNames();
    tables_ = std::make_unique<TableStore>(dir_.string(), "q_table.yaml", AbsolutePaths::MustLieInTheFolder);
  }
  // The run's folder, opened as at the start of training.
  RunFolder& openFolder(LogLines& log)
  {
    folder_ = std::make_unique<RunFolder>(settings_, *tables_, [] { return std::time_t(1790000000); });
    TrainingSession session(TaskParams(), AgentParams(), 0);
    folder_->open({}, 0, session, log);
    return *folder_;
  }

  RunSettings settings_;
  std::unique_ptr<TableStore> tables_;
  std::unique_ptr<RunFolder> folder_;
};
}  // namespace

TEST_F(LearningCurveTest, ByDefaultTheCurveIsTheRunFoldersAndStartsAtOnce)
{
  LogLines log;
  RunFolder& folder = openFolder(log);
  LearningCurve curve(settings_, folder, [] { return 12.5; });
  curve.openUsersFile();
  curve.start(0, log);
  const std::string file = folder.file(kRunEpisodesFile);
  EXPECT_EQ(std::vector<std::string>{kLearningCurveHeader}, lines(file));
  EXPECT_NE(std::string::npos, log.back().text.find("one row per episode goes to " + (dir_ / file).string()));
  curve.write("robot_0", episode(1), log);
  EXPECT_EQ(learningCurveRow(episode(1), "robot_0", 12.5), lines(file).at(1));
  curve.write("", episode(2), log);
  curve.startOver(7, log);
  EXPECT_EQ(std::vector<std::string>{kLearningCurveHeader}, lines(file));
  EXPECT_NE(std::string::npos, log.back().text.find("starts over from the loaded table's episode 7"));
}

TEST_F(LearningCurveTest, ARunThatWritesNothingAlongTheWayMakesItsFolderForTheFirstRow)
{
  settings_.checkpoint_every = 0;
  settings_.save_on_shutdown = false;
  LogLines log;
  RunFolder& folder = openFolder(log);
  LearningCurve curve(settings_, folder, [] { return 0.0; });
  curve.start(0, log);
  EXPECT_TRUE(test::filesBelow(dir_).empty());
  curve.write("", episode(1), log);
  EXPECT_EQ(2u, lines(folder.file(kRunEpisodesFile)).size());
  EXPECT_EQ(std::optional<std::string>(folder.name()), folder.takeNewName());
}

TEST_F(LearningCurveTest, AUsersFileIsOpenedBeforeTheRunAndOneThatIsNotACurveStopsIt)
{
  settings_.stats_csv = "mine.csv";
  LogLines log;
  RunFolder& folder = openFolder(log);
  {
    LearningCurve curve(settings_, folder, [] { return 0.0; });
    curve.openUsersFile();
    curve.start(0, log);
    curve.write("", episode(1), log);
  }
  EXPECT_EQ(2u, lines("mine.csv").size());
  EXPECT_FALSE(fs::exists(dir_ / folder.file(kRunEpisodesFile)));

  std::ofstream(dir_ / "notes.txt") << "my notes\n";
  settings_.stats_csv = "notes.txt";
  LearningCurve notes(settings_, folder, [] { return 0.0; });
  notes.openUsersFile();
  try
  {
    notes.start(0, log);
    FAIL() << "notes taken for a curve";
  }
  catch (const RunSettingError& e)
  {
    EXPECT_EQ("stats_csv", nodeParameterName(e.setting));
    EXPECT_EQ("'notes.txt'", e.value);
  }
  EXPECT_EQ("my notes\n", text("notes.txt"));
  fs::create_directories(dir_ / "a_folder");
  settings_.stats_csv = "a_folder";
  EXPECT_THROW(LearningCurve(settings_, folder, [] { return 0.0; }).openUsersFile(), RunSettingError);
}

TEST_F(LearningCurveTest, NoneOrAnEvaluationWritesNoCurve)
{
  LogLines log;
  RunFolder& folder = openFolder(log);
  settings_.stats_csv = "none";
  LearningCurve none(settings_, folder, [] { return 0.0; });
  none.openUsersFile();
  none.start(0, log);
  none.write("", episode(1), log);
  settings_.stats_csv = "";
  settings_.mode = RunMode::Evaluate;
  LearningCurve evaluation(settings_, folder, [] { return 0.0; });
  evaluation.start(0, log);
  evaluation.write("", episode(1), log);
  EXPECT_EQ(std::vector<std::string>{folder.file(kRunRecordFile)}, test::filesBelow(dir_));
}
