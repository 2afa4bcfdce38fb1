// The train_headless executable as a user runs it: its last line, its exit codes, its messages.
#include "cartpole_qlearning/q_table_file.h"

#include "test_support.h"
#include "trace_check.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

using cartpole_qlearning::test::CommandRun;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::TraceReading;

namespace
{
CommandRun trainHeadless(const std::string& args)
{
  return runCommand(std::string(TRAIN_HEADLESS) + " " + args);
}

std::string config()
{
  return std::string("--config ") + CARTPOLE_CONFIG_DIR "/cartpole.yaml";
}

std::string tutorialConfig()
{
  return std::string("--config ") + CARTPOLE_CONFIG_DIR "/tutorial_4_states.yaml";
}

// learning/state_names of tutorial_4_states.yaml: the rows, then the terminal state.
const std::vector<std::string> kTutorialNames{"S1 tilted left", "S0 upright", "S2 tilted right", "S3 fallen"};

class TrainHeadlessTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("train_headless_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  std::string file(const std::string& name, const std::string& text = "") const
  {
    const std::string path = (dir_ / name).string();
    if (!text.empty())
      std::ofstream(path) << text;
    return path;
  }
  fs::path dir_;
};
}  // namespace

TEST_F(TrainHeadlessTest, SolvesAndEndsWithTheResultLine)
{
  const CommandRun run = trainHeadless(config() + " --seed 0");
  EXPECT_EQ(0, run.status) << run.output;
  EXPECT_TRUE(std::regex_match(run.lastLine(), std::regex("solved=true episodes=[0-9]+ steps=[0-9]+ wall_s=[0-9.]+")))
      << run.lastLine();
  // Progress lines come before it.
  EXPECT_NE(std::string::npos, run.output.find("mean_return_100")) << run.output;
}

TEST_F(TrainHeadlessTest, SavedTableLoadsAndTheSameSeedWritesTheSameBytes)
{
  const std::string a = file("a.yaml");
  const std::string b = file("b.yaml");
  ASSERT_EQ(0, trainHeadless(config() + " --seed 4 --quiet --save " + a).status);
  ASSERT_EQ(0, trainHeadless(config() + " --seed 4 --quiet --save " + b).status);
  const cartpole_qlearning::QTable table = cartpole_qlearning::loadQTableFile(a);
  EXPECT_GT(table.episodes, 0u);
  EXPECT_EQ(fileText(a), fileText(b));
}

TEST_F(TrainHeadlessTest, ARelativeSaveGoesWhereTheControllerLooksAndNoSaveSaysSo)
{
  // The one path rule: relative to $ROS_HOME/cartpole_qlearning/<ns>, as the services and the
  // launch files take q_table paths (evaluate.launch q_table:=mine.yaml then finds it).
  const std::string home = "ROS_HOME=" + dir_.string() + " ";
  const CommandRun saved =
      runCommand(home + TRAIN_HEADLESS + " " + config() + " --max-episodes 3 --save runs/mine.yaml");
  ASSERT_EQ(0, saved.status) << saved.output;
  const std::string expected = (dir_ / "cartpole_qlearning" / "cartpole" / "runs" / "mine.yaml").string();
  EXPECT_EQ(3u, cartpole_qlearning::loadQTableFile(expected).episodes);
  EXPECT_NE(std::string::npos, saved.output.find("saved the Q-table to " + expected)) << saved.output;
  const CommandRun other =
      runCommand(home + TRAIN_HEADLESS + " " + config() + " --max-episodes 3 --ns a/b --save t.yaml");
  ASSERT_EQ(0, other.status) << other.output;
  EXPECT_TRUE(fs::exists(dir_ / "cartpole_qlearning" / "a" / "b" / "t.yaml"));
  // Leaving the folder is refused, as over a service; nothing is written.
  const CommandRun escape = runCommand(home + TRAIN_HEADLESS + " " + config() + " --max-episodes 3 --save ../x.yaml");
  EXPECT_EQ(1, escape.status) << escape.output;
  EXPECT_FALSE(fs::exists(dir_ / "cartpole_qlearning" / "x.yaml"));
  // Without --save nothing is written, and it says where --save would write.
  const CommandRun unsaved = runCommand(home + TRAIN_HEADLESS + " " + config() + " --max-episodes 3");
  EXPECT_EQ(0, unsaved.status);
  EXPECT_NE(std::string::npos, unsaved.output.find("nothing saved (--save NAME writes the table to " +
                                                   (dir_ / "cartpole_qlearning" / "cartpole").string()))
      << unsaved.output;
}

// The fields of a CSV line (no quoting: the package's own rows have none).
std::vector<std::string> fields(const std::string& line)
{
  std::vector<std::string> found;
  std::istringstream in(line);
  for (std::string f; std::getline(in, f, ',');)
    found.push_back(f);
  if (!line.empty() && line.back() == ',')
    found.push_back("");
  return found;
}

TEST_F(TrainHeadlessTest, TheStatsCsvHasOneRowPerEpisodeEndingWhereTheResultLineSays)
{
  const std::string csv = file("curve/episodes.csv");  // a folder that does not exist yet
  const CommandRun run = trainHeadless(config() + " --seed 0 --quiet --stats-csv " + csv);
  ASSERT_EQ(0, run.status) << run.output;
  std::smatch result;
  const std::string last = run.lastLine();
  ASSERT_TRUE(std::regex_match(last, result, std::regex("solved=true episodes=([0-9]+) steps=([0-9]+) wall_s=.*")))
      << last;
  const unsigned long episodes = std::stoul(result[1]);
  const unsigned long steps = std::stoul(result[2]);

  std::istringstream in(fileText(csv));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(
      "episode,robot,steps,episode_return,mean_return_100,epsilon,alpha,terminated,truncated,solved,total_steps,"
      "wall_time,gamma",
      line);
  unsigned long rows = 0;
  unsigned long summed_steps = 0;
  std::vector<std::string> row;
  while (std::getline(in, line))
  {
    row = fields(line);
    ASSERT_EQ(13u, row.size()) << line;
    ++rows;
    EXPECT_EQ(std::to_string(rows), row[0]) << "rows out of order or missing at " << line;
    summed_steps += std::stoul(row[2]);
    EXPECT_EQ(std::to_string(summed_steps), row[10]) << line;
    // Every episode of this task earns +1 a step (gymnasium rewards).
    EXPECT_EQ(std::stod(row[2]), std::stod(row[3])) << line;
    EXPECT_NE(row[8] == "true", row[7] == "true") << "an episode ends terminated or truncated: " << line;
    if (rows < episodes)
    {
      EXPECT_EQ("false", row[9]) << "solved before the last episode: " << line;
    }
  }
  EXPECT_EQ(episodes, rows);
  EXPECT_EQ(steps, summed_steps);
  EXPECT_EQ("true", row.at(9)) << "the last row is not the solved episode";
  EXPECT_GE(std::stod(row.at(4)), 475.0);
}

TEST_F(TrainHeadlessTest, AStatsCsvThatCannotBeWrittenStopsBeforeTraining)
{
  fs::create_directories(dir_ / "a_folder");
  const CommandRun run = trainHeadless(config() + " --stats-csv " + (dir_ / "a_folder").string());
  EXPECT_EQ(2, run.status) << run.output;
  EXPECT_NE(std::string::npos, run.output.find("--stats-csv")) << run.output;
  EXPECT_NE(std::string::npos, run.output.find("a_folder")) << run.output;
  EXPECT_EQ(std::string::npos, run.output.find("solved=")) << run.output;
}

TEST_F(TrainHeadlessTest, UnsolvedRunSaysSo)
{
  const CommandRun run = trainHeadless(config() + " --seed 0 --quiet --max-episodes 5");
  EXPECT_EQ(0, run.status);
  EXPECT_TRUE(std::regex_match(run.lastLine(), std::regex("solved=false episodes=5 steps=[0-9]+ wall_s=[0-9.]+")))
      << run.lastLine();
}

TEST_F(TrainHeadlessTest, WallTimeHasMicrosecondsSoAFewMillisecondsCanBeRead)
{
  const CommandRun run = trainHeadless(config() + " --seed 0 --quiet --max-episodes 5");
  EXPECT_TRUE(
      std::regex_match(run.lastLine(), std::regex("solved=false episodes=5 steps=[0-9]+ wall_s=[0-9]+\\.[0-9]{6}")))
      << run.lastLine();
}

TEST_F(TrainHeadlessTest, ReturnsListsEveryEpisodesReturnBeforeTheResultLine)
{
  const CommandRun run = trainHeadless(config() + " --seed 0 --quiet --max-episodes 7 --returns");
  EXPECT_EQ(0, run.status) << run.output;
  std::smatch result;
  const std::string last = run.lastLine();
  ASSERT_TRUE(std::regex_match(last, result, std::regex("solved=false episodes=7 steps=([0-9]+) wall_s=[0-9.]+")))
      << run.output;
  std::smatch returns;
  ASSERT_TRUE(std::regex_search(run.output, returns, std::regex("returns=([0-9 ]+)\n"))) << run.output;
  std::istringstream values(returns[1].str());
  std::vector<double> episode_returns{std::istream_iterator<double>(values), std::istream_iterator<double>()};
  ASSERT_EQ(7u, episode_returns.size()) << returns[1];
  // The default reward is +1 a step, so the returns add up to the steps run.
  double sum = 0.0;
  for (const double r : episode_returns)
    sum += r;
  EXPECT_EQ(std::stod(result[1].str()), sum);

  const CommandRun without = trainHeadless(config() + " --seed 0 --quiet --max-episodes 7");
  EXPECT_EQ(std::string::npos, without.output.find("returns=")) << without.output;
}

TEST_F(TrainHeadlessTest, BadConfigStopsWithTheKeyTheValueAndTheRange)
{
  const CommandRun bad_value = trainHeadless("--config " + file("bad.yaml", "learning:\n  gamma: 2.0\n"));
  EXPECT_EQ(2, bad_value.status);
  EXPECT_NE(std::string::npos, bad_value.output.find("learning/gamma = 2 is not allowed (must be in [0, 1])"))
      << bad_value.output;
  EXPECT_EQ(std::string::npos, bad_value.output.find("solved="));

  const CommandRun typo = trainHeadless("--config " + file("typo.yaml", "task:\n  max_steps: 200\n"));
  EXPECT_EQ(2, typo.status);
  EXPECT_NE(std::string::npos, typo.output.find("unknown key task/max_steps")) << typo.output;

  const CommandRun missing = trainHeadless("--config " + file("nope.yaml"));
  EXPECT_EQ(2, missing.status);
  EXPECT_NE(std::string::npos, missing.output.find("nope.yaml: cannot be read")) << missing.output;
}

TEST_F(TrainHeadlessTest, BadArgumentsAreRefused)
{
  EXPECT_EQ(2, trainHeadless(config() + " --seed minus-one").status);
  EXPECT_EQ(2, trainHeadless(config() + " --max-episodes 0").status);
  EXPECT_EQ(2, trainHeadless(config() + " --bogus").status);
  EXPECT_EQ(0, trainHeadless("--help").status);
}

// The tutorial's worked example (10 steps, alpha 0.5, gamma 0.9) replayed from the shipped file:
// the values printed after every step are the tutorial's, exactly.
TEST_F(TrainHeadlessTest, ReplayOfTheTutorialsTenStepsPrintsItsExactValues)
{
  const CommandRun run = trainHeadless(tutorialConfig() + " --replay " + CARTPOLE_CONFIG_DIR "/tutorial_10_steps.yaml");
  ASSERT_EQ(0, run.status) << run.output;
  const TraceReading trace(run.output, kTutorialNames);
  EXPECT_EQ(std::vector<std::string>(), trace.check(2, 0.9, 0.5)) << run.output;

  // Q(s,a) after each step, as fractions: 1/2, 29/40, -1/4, 561/800, 18849/16000, 1/2,
  // 13049/16000, 441841/320000, 10946369/6400000, 357441/320000.
  const std::vector<std::string> expected_new{"0.5", "0.725",     "-0.25",       "0.70125",       "1.1780625",
                                              "0.5", "0.8155625", "1.380753125", "1.71037015625", "1.117003125"};
  ASSERT_EQ(expected_new.size(), trace.updates.size()) << run.output;
  for (std::size_t i = 0; i < expected_new.size(); ++i)
    EXPECT_EQ(expected_new[i], trace.updates[i].new_value) << "step " << i + 1;
  EXPECT_TRUE(trace.updates[2].terminal);
  EXPECT_EQ("-1", trace.updates[2].target);

  // A table when the fall ends episode 1, and the table after step 10.
  ASSERT_EQ(2u, trace.tables.size()) << run.output;
  EXPECT_EQ("episode 1", trace.tables[0].title);
  EXPECT_EQ((std::vector<std::string>{"0", "-0.25"}), trace.tables[0].rows.at("S0 upright"));
  EXPECT_EQ((std::vector<std::string>{"0.725", "0"}), trace.tables[0].rows.at("S1 tilted left"));
  const auto& last = trace.tables[1].rows;
  EXPECT_EQ((std::vector<std::string>{"1.117003125", "1.380753125"}), last.at("S0 upright"));
  EXPECT_EQ((std::vector<std::string>{"1.71037015625", "0"}), last.at("S1 tilted left"));
  EXPECT_EQ((std::vector<std::string>{"0", "0.8155625"}), last.at("S2 tilted right"));
  EXPECT_EQ((std::vector<std::string>{"0", "0"}), last.at("S3 fallen"));
}

TEST_F(TrainHeadlessTest, ReplayWritesItsTableWhenAskedTo)
{
  const std::string saved = file("replayed.yaml");
  const CommandRun run =
      trainHeadless(tutorialConfig() + " --replay " + CARTPOLE_CONFIG_DIR + "/tutorial_10_steps.yaml --save " + saved);
  ASSERT_EQ(0, run.status) << run.output;
  const cartpole_qlearning::QTable table = cartpole_qlearning::loadQTableFile(saved);
  EXPECT_EQ(1.117003125, table.at(1, 0));  // S0 upright is row 1
  EXPECT_EQ(1u, table.episodes);
  EXPECT_EQ(10u, table.steps);
}

// A replay file with a mistake is refused with the line it is on, before any update.
TEST_F(TrainHeadlessTest, BadReplayFileNamesTheLineAndRunsNothing)
{
  const std::string head = "transitions:\n  - [S0 upright, A1, 1, S1 tilted left]\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {head + "  - [S0 upright, A1, 1, S9 nowhere]\n", "line 3: unknown state 'S9 nowhere'"},
      {head + "  - [S0 upright, A2, 1, S1 tilted left]\n", "line 3: action 'A2' is out of range"},
      {head + "  - [S0 upright, A1, one, S1 tilted left]\n", "line 3: reward 'one' is not a number"},
      {head + "  - [S3 fallen, A1, 1, S0 upright]\n", "line 3: 'S3 fallen' is the terminal state"},
      {head + "  - [S0 upright, A1, 1]\n", "line 3: a transition must be a list [state, action, reward, next state]"},
      {"steps:\n  - [S0 upright, A1, 1, S1 tilted left]\n", "line 1: unknown key 'steps'"},
  };
  const std::string saved = file("not_written.yaml");
  for (const auto& c : cases)
  {
    const std::string replay = file("replay.yaml", c.first);
    const CommandRun run = trainHeadless(tutorialConfig() + " --replay " + replay + " --save " + saved);
    EXPECT_EQ(2, run.status) << run.output;
    EXPECT_NE(std::string::npos, run.output.find(replay + " " + c.second)) << run.output;
    EXPECT_EQ(std::string::npos, run.output.find("episode 1 step")) << run.output;
    EXPECT_FALSE(fs::exists(saved)) << c.first;
  }
}

// A replay path that is not a file (a folder, a FIFO that would block, /dev/zero that never
// ends) is refused at once with its name, rather than hang or fill the memory.
TEST_F(TrainHeadlessTest, AReplayThatIsNotAFileIsRefusedAtOnce)
{
  const std::string fifo = file("fifo.yaml");
  ASSERT_EQ(0, ::mkfifo(fifo.c_str(), 0600));
  for (const std::string& path : {dir_.string(), fifo, std::string("/dev/zero")})
  {
    const CommandRun run = trainHeadless(tutorialConfig() + " --replay " + path);
    EXPECT_EQ(2, run.status) << run.output;
    EXPECT_NE(std::string::npos, run.output.find("cannot read " + path + ": not a regular file")) << run.output;
  }
}

// The trace prints one table row per state: a tile-coded config has none, and is told so
// before anything runs.
TEST_F(TrainHeadlessTest, TraceAndReplayRefuseATileCodedConfig)
{
  const std::string tiles = std::string(" --config ") + CARTPOLE_CONFIG_DIR + "/tiles.yaml";
  const std::vector<std::string> options{" --trace",
                                         std::string(" --replay ") + CARTPOLE_CONFIG_DIR + "/tutorial_10_steps.yaml"};
  for (const std::string& option : options)
  {
    const CommandRun run = trainHeadless(tiles + option);
    EXPECT_EQ(2, run.status) << run.output;
    EXPECT_NE(std::string::npos, run.output.find("it needs learning/features bins")) << run.output;
    EXPECT_EQ(std::string::npos, run.output.find("solved=")) << run.output;
  }
}

// Training with --trace on the tutorial's 4 states: every printed update holds its arithmetic,
// and a table, equal to what the updates printed so far, ends each episode.
TEST_F(TrainHeadlessTest, TraceWhileTrainingHoldsItsArithmeticWithATableAtEachEpisodeEnd)
{
  const CommandRun run = trainHeadless(tutorialConfig() + " --trace --seed 3 --max-episodes 6");
  ASSERT_EQ(0, run.status) << run.output;
  EXPECT_EQ(0u, run.lastLine().find("solved=false episodes=6 steps=")) << run.lastLine();
  const TraceReading trace(run.output, kTutorialNames);
  EXPECT_EQ(std::vector<std::string>(), trace.check(2, 0.9, 0.5)) << run.output;
  ASSERT_EQ(6u, trace.tables.size());
  for (std::size_t e = 0; e < trace.tables.size(); ++e)
    EXPECT_EQ("episode " + std::to_string(e + 1), trace.tables[e].title);
  // One update per step, each episode ending on the fall, just before its table.
  const std::string steps = run.lastLine().substr(run.lastLine().find("steps=") + 6);
  EXPECT_EQ(std::stoul(steps), trace.updates.size());
  EXPECT_EQ('t', trace.order.back());
  for (std::size_t i = 1; i < trace.order.size(); ++i)
    EXPECT_TRUE(trace.order[i] != 't' ||
                trace.updates[std::count(trace.order.begin(), trace.order.begin() + i, 'u') - 1].terminal);

  // Without --trace, no trace.
  const CommandRun quiet = trainHeadless(tutorialConfig() + " --seed 3 --max-episodes 6");
  EXPECT_TRUE(TraceReading(quiet.output, kTutorialNames).updates.empty()) << quiet.output;
}
