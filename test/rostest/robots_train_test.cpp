// train.launch robots:=3, seed 0 (started by robots_train.test, two processes or nodelets):
// one learner fed by three sims in lockstep rounds writes the table train_headless --robots 3
// writes, byte for byte; every robot's own episode_stats count its episodes, and the learner's
// count them all.
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
using cartpole_qlearning::EpisodeStatsConstPtr;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::spinUntil;

namespace
{
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");
}  // namespace

TEST(RobotsTrain, ThreeRobotsWriteTheHeadlessTableForThreeRobots)
{
  ros::NodeHandle nh;
  const std::string dir = kTableDir.path();
  ASSERT_FALSE(dir.empty()) << "no ~q_table_dir";
  std::vector<EpisodeStats> all;
  std::vector<std::vector<EpisodeStats>> per_robot(3);
  std::vector<ros::Subscriber> subs;
  subs.push_back(nh.subscribe<EpisodeStats>(
      "/robots3/episode_stats", 10000,
      boost::function<void(const EpisodeStatsConstPtr&)>([&](const EpisodeStatsConstPtr& m) { all.push_back(*m); })));
  for (std::size_t r = 0; r < 3; ++r)
    subs.push_back(
        nh.subscribe<EpisodeStats>("/robots3/robot_" + std::to_string(r) + "/episode_stats", 10000,
                                   boost::function<void(const EpisodeStatsConstPtr&)>(
                                       [&, r](const EpisodeStatsConstPtr& m) { per_robot[r].push_back(*m); })));

  // The table train_headless writes for three robots; training over ROS must end with it (the
  // checkpoints on the way are other tables). As nodelets, training may be over before this
  // node's subscriptions are up, so the file is what is awaited.
  const std::string headless = dir + "/headless.yaml";
  const std::string command = std::string(TRAIN_HEADLESS) + " --seed 0 --robots 3 --quiet --config " +
                              CARTPOLE_CONFIG_DIR "/cartpole.yaml --no-run-folder --save " + headless;
  ASSERT_EQ(0, std::system(command.c_str())) << command;
  const std::string expected = fileText(headless);
  const std::string trained = dir + "/q_table.yaml";
  const bool same = spinUntil([&] { return fs::exists(trained) && fileText(trained) == expected; }, 120.0);
  EXPECT_TRUE(same) << "robots:=3 did not write train_headless --robots 3's table for seed 0 (" << trained
                    << (fs::exists(trained) ? " differs)" : " was not written)");

  // The learner's topic numbers every episode; each robot's numbers its own, and names it.
  bool check_episode_stats = true;
  ros::param::get("~check_episode_stats", check_episode_stats);
  if (!check_episode_stats || !same)
    return;
  ASSERT_TRUE(spinUntil([&] { return !all.empty() && all.back().solved; }, 10.0)) << "no solved episode_stats";
  const auto robotEpisodes = [&] {
    std::uint64_t sum = 0;
    for (const std::vector<EpisodeStats>& robot : per_robot)
      sum += robot.empty() ? 0 : robot.back().episode;
    return sum;
  };
  // A robot's report of the last episode follows the learner's on a connection of its own: it may
  // still be on its way.
  spinUntil([&] { return robotEpisodes() >= all.back().episode; }, 10.0);
  for (std::size_t r = 0; r < 3; ++r)
  {
    SCOPED_TRACE("robot_" + std::to_string(r));
    EXPECT_GT(per_robot[r].size(), 20u) << "the robot hardly took part";
    for (std::size_t i = 1; i < per_robot[r].size(); ++i)
      EXPECT_EQ(per_robot[r][i - 1].episode + 1, per_robot[r][i].episode);
    for (const EpisodeStats& s : per_robot[r])
      EXPECT_EQ("robot_" + std::to_string(r), s.robot);
  }
  for (std::size_t i = 1; i < all.size(); ++i)
    EXPECT_EQ(all[i - 1].episode + 1, all[i].episode);
  EXPECT_EQ(all.back().episode, robotEpisodes()) << "the learner's episodes are not the robots' episodes together";
}
