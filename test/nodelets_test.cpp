// Both nodes as nodelets in one manager with one worker thread (their lockstep topics on the
// nodelets' shared lockstep thread, passing pointers): training solves, the table is
// train_headless's byte for byte, and the manager outlives the finished training.
#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/Reset.h"

#include "ros_test_support.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using cartpole_qlearning::test::readFile;
using cartpole_qlearning::test::spinUntil;

TEST(Nodelets, TrainingOnOneWorkerThreadSolvesWithTheHeadlessTable)
{
  ros::NodeHandle nh;
  std::string dir;
  ASSERT_TRUE(ros::param::get("~q_table_dir", dir));
  std::uint32_t last_episode = 0;
  bool solved = false;
  ros::Subscriber sub = nh.subscribe<cartpole_qlearning::EpisodeStats>(
      "/cartpole/episode_stats", 1000,
      boost::function<void(const cartpole_qlearning::EpisodeStatsConstPtr&)>(
          [&](const cartpole_qlearning::EpisodeStatsConstPtr& m) {
            last_episode = m->episode;
            solved = solved || m->solved;
          }));
  // Episode after episode: every reset call returned although the sim's service and the
  // controller share the manager's one worker thread.
  ASSERT_TRUE(spinUntil([&] { return solved; }, 60.0)) << "training stalled at episode " << last_episode;

  const std::string trained = dir + "/q_table.yaml";
  ASSERT_TRUE(spinUntil([&] { return fs::exists(trained); }, 10.0)) << trained;
  const std::string headless = dir + "/headless.yaml";
  const std::string command = std::string(TRAIN_HEADLESS) + " --seed 0 --quiet --config " +
                              CARTPOLE_CONFIG_DIR "/cartpole.yaml --save " + headless;
  ASSERT_EQ(0, std::system(command.c_str())) << command;
  EXPECT_EQ(readFile(headless), readFile(trained)) << "nodelet training and train_headless differ for seed 0";

  // The controller stopped acting but did not end its manager: the sim still serves.
  cartpole_qlearning::Reset reset;
  EXPECT_TRUE(ros::service::call("/cartpole/cartpole_sim/reset", reset)) << "the manager ended with the training";
  EXPECT_TRUE(reset.response.success) << reset.response.message;
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "nodelets_test");
  ros::NodeHandle nh;
  const int result = RUN_ALL_TESTS();
  std::string dir;
  if (ros::param::get("~q_table_dir", dir))
    fs::remove_all(dir);
  return result;
}
