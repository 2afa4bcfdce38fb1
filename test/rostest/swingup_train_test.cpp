// train.launch config:=swingup.yaml, in lockstep and as nodelets (swingup_train.test): the sim
// starts each episode with the pole hanging as train_headless's simulation does, on the same rail,
// so that a few episodes of training on the graph write train_headless's table, byte for byte.
#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cartpole_qlearning::test::CommandRun;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::runTable;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home",
                                                       cartpole_qlearning::test::ScratchFolder::Make::beforeTheTests);
const std::string kConfig = CARTPOLE_CONFIG_DIR "/swingup.yaml";
// A few of the Suite's 1,000-step episodes: the table learns from every one of their 8,000 steps.
const std::string kEpisodes = "8";

// The first line where two texts differ (1-based), with both versions of it.
std::string firstDifference(const std::string& a, const std::string& b)
{
  std::istringstream in_a(a), in_b(b);
  std::string line_a, line_b;
  for (int n = 1;; ++n)
  {
    const bool more_a = static_cast<bool>(std::getline(in_a, line_a));
    const bool more_b = static_cast<bool>(std::getline(in_b, line_b));
    if (!more_a && !more_b)
      return "none";
    if (line_a != line_b || more_a != more_b)
      return std::to_string(n) + ":\n  " + line_a + "\n  " + line_b;
  }
}

std::string headlessTable()
{
  const std::string home = kRosHome.path() + "/headless";
  if (!fs::exists(home))
  {
    fs::create_directories(home);
    const CommandRun run = runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --config " + kConfig +
                                      " --seed 2 --max-episodes " + kEpisodes + " --quiet");
    EXPECT_EQ(0, run.status) << run.output;
    EXPECT_EQ(
        0u, run.lastLine().find("until=max_episodes reached=true solved=false episodes=" + kEpisodes + " steps=8000 "))
        << run.output;
  }
  return runTable(home);
}

void trainsTheHeadlessTable(const std::string& name, const std::string& args)
{
  const std::string home = kRosHome.path() + "/" + name;
  fs::create_directories(home);
  // stop_when_solved as the config has it (train.launch's own default is true).
  TrainLaunch launch(home, "train",
                     "config:=" + kConfig + " seed:=2 max_episodes:=" + kEpisodes + " stop_when_solved:=false " + args);
  ASSERT_EQ(0, launch.waitFor(150.0)) << launch.output();
  const std::string output = launch.output();
  EXPECT_NE(std::string::npos, output.find("starts of task swingup, start state [")) << output;
  const std::string table = runTable(home);
  EXPECT_NE(std::string::npos, table.find("  task:\n    kind: swingup\n")) << table;
  const std::string headless = headlessTable();
  EXPECT_TRUE(headless == table) << "train.launch " << args << " and train_headless differ, from line "
                                 << firstDifference(headless, table);
}
}  // namespace

TEST(SwingupTrain, TrainLaunchInLockstepWritesTheHeadlessTable)
{
  trainsTheHeadlessTable("lockstep", "");
}

TEST(SwingupTrain, TrainLaunchAsNodeletsWritesTheHeadlessTable)
{
  trainsTheHeadlessTable("nodelet", "nodelet:=true");
}
