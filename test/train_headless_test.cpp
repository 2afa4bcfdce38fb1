// The train_headless executable as a user runs it: its last line, its exit codes, its messages.
#include "cartpole_qlearning/q_table_file.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

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

TEST_F(TrainHeadlessTest, UnsolvedRunSaysSo)
{
  const CommandRun run = trainHeadless(config() + " --seed 0 --quiet --max-episodes 5");
  EXPECT_EQ(0, run.status);
  EXPECT_TRUE(std::regex_match(run.lastLine(), std::regex("solved=false episodes=5 steps=[0-9]+ wall_s=[0-9.]+")))
      << run.lastLine();
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
