// train.launch config:=robust.yaml nodelet:=true, seed 0: the controller trains past solved until
// the robustness suite passes, its last episode_stats says so (robustness), and the table it
// saves is the one train_headless writes with the same seed and config, byte for byte.
#include "cartpole_qlearning/EpisodeStats.h"

#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cartpole_qlearning::EpisodeStats;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::spinUntil;

namespace
{
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");
}  // namespace

TEST(RobustTrain, TrainsOnTheGraphToAPassingTableThatIsTrainHeadlesss)
{
  const std::string dir = kTableDir.path();
  std::vector<EpisodeStats> stats;
  ros::NodeHandle nh;
  ros::Subscriber sub =
      nh.subscribe<EpisodeStats>("/cartpole/episode_stats", 10000,
                                 boost::function<void(const cartpole_qlearning::EpisodeStatsConstPtr&)>(
                                     [&](const cartpole_qlearning::EpisodeStatsConstPtr& m) { stats.push_back(*m); }));
  ASSERT_TRUE(spinUntil([&] { return !stats.empty() && !stats.back().robustness.empty(); }, 500.0))
      << "no episode_stats with a robustness verdict; episodes seen: " << stats.size();
  const EpisodeStats& last = stats.back();
  EXPECT_NE(std::string::npos, last.robustness.find(": PASSED")) << last.robustness;
  EXPECT_NE(std::string::npos, last.robustness.find("all_at_once ")) << last.robustness;
  for (std::size_t i = 0; i + 1 < stats.size(); ++i)
    ASSERT_EQ("", stats[i].robustness) << "episode " << stats[i].episode;

  const std::string trained = dir + "/trained.yaml";
  ASSERT_TRUE(spinUntil([&] { return fs::exists(trained); }, 10.0)) << trained;
  const std::string headless = dir + "/headless.yaml";
  const std::string command = std::string(TRAIN_HEADLESS) +
                              " --seed 0 --quiet --config " CARTPOLE_CONFIG_DIR "/robust.yaml --no-run-folder --save " +
                              headless;
  ASSERT_EQ(0, std::system(command.c_str())) << command;
  EXPECT_EQ(fileText(headless), fileText(trained)) << "train.launch (nodelets) and train_headless differ for seed 0";
  sub.shutdown();
}
