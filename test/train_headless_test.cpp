// The train_headless executable as a user runs it: its last line, its exit codes, its messages.
#include "cartpole_qlearning/q_table_file.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

using cartpole_qlearning::test::CommandRun;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::runCommand;

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
