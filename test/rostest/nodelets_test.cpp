// Both nodes as nodelets in one manager with one worker thread (their lockstep topics on the
// nodelets' shared lockstep thread, passing pointers): training solves, the table is
// train_headless's byte for byte, and the manager outlives the finished training.
#include "cartpole_qlearning/Reset.h"

#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::spinUntil;

namespace
{
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");
}  // namespace

TEST(Nodelets, TrainingOnOneWorkerThreadSolvesWithTheHeadlessTable)
{
  ros::NodeHandle nh;
  const std::string dir = kTableDir.path();
  ASSERT_FALSE(dir.empty()) << "no ~q_table_dir";
  // Training there takes well under a second, maybe less than this node needs to subscribe to
  // episode_stats: what is awaited is the final table, which must be train_headless's.
  const std::string headless = dir + "/headless.yaml";
  const std::string command = std::string(TRAIN_HEADLESS) + " --seed 0 --quiet --config " +
                              CARTPOLE_CONFIG_DIR "/cartpole.yaml --no-run-folder --save " + headless;
  ASSERT_EQ(0, std::system(command.c_str())) << command;
  const std::string expected = fileText(headless);
  const std::string trained = dir + "/q_table.yaml";
  // Episode after episode: every reset call returned although the sim's service and the
  // controller share the manager's one worker thread.
  EXPECT_TRUE(spinUntil([&] { return fs::exists(trained) && fileText(trained) == expected; }, 60.0))
      << "nodelet training did not write train_headless's table for seed 0 (" << trained
      << (fs::exists(trained) ? " differs)" : " was not written: training stalled?)");

  // The controller stopped acting but did not end its manager: the sim still serves.
  cartpole_qlearning::Reset reset;
  EXPECT_TRUE(ros::service::call("/cartpole/cartpole_sim/reset", reset)) << "the manager ended with the training";
  EXPECT_TRUE(reset.response.success) << reset.response.message;
}
