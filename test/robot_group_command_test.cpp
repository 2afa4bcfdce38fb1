// A robot driven through a JointGroupEffortController whose + effort pushes the cart toward -x, on the graph
// (robot_group_command.test): the sim takes std_msgs/Float64MultiArray efforts on group_effort, the cart's in
// slot 1, with ~effort_sign -1. A table trained by train_headless (our sign) is evaluated through robot.launch
// command_type:=float64_array command_index:=1 command_size:=3 effort_sign:=-1: it balances; the same evaluation
// with effort_sign:=1 (the robot's sign ignored) pushes the wrong way and falls.
#include "ros_test_support.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <regex>
#include <string>

using cartpole_qlearning::test::privateParam;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
struct Verdict
{
  unsigned balanced = 0;
  double mean_return = 0.0;
};

// robot.launch mode:=evaluate with the table, 5 episodes, and `args`; its verdict.
Verdict evaluate(const std::string& home, const std::string& name, const std::string& args)
{
  TrainLaunch launch(home, name,
                     "mode:=evaluate load:=q_table.yaml episodes:=5 command_type:=float64_array command_index:=1 "
                     "command_size:=3 joint_command:=group_controller/command reset_service:=cartpole_sim/reset " +
                         args,
                     "robot.launch");
  const int status = launch.waitFor(90.0);
  const std::string output = launch.output();
  EXPECT_EQ(0, status) << output;
  std::smatch m;
  if (!std::regex_search(output, m,
                         std::regex("EVALUATED 5 episodes: ([0-9]+) balanced to the step limit \\(500 steps\\), "
                                    "mean return ([0-9.]+)")))
  {
    ADD_FAILURE() << output;
    return {};
  }
  std::printf("%s: %s\n", name.c_str(), m[0].str().c_str());
  return {static_cast<unsigned>(std::stoul(m[1])), std::stod(m[2])};
}
}  // namespace

TEST(RobotGroupCommand, TheTableBalancesThroughTheArraySlotWithTheRobotsEffortSignAndFallsWithout)
{
  const std::string home = privateParam("ros_home");
  ASSERT_FALSE(home.empty());
  std::filesystem::create_directories(home);
  const auto trained =
      runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --seed 0 --quiet --no-run-folder --save q_table.yaml");
  ASSERT_EQ(0, trained.status) << trained.output;
  ASSERT_EQ("solved=true", trained.lastLine().substr(0, 11)) << trained.output;

  // Held up for most of the 500 steps (seed 0's table: 456 and 487 on average in two runs, the cart leaving the track
  // near the end of some episodes, when this was written)...
  const Verdict right = evaluate(home, "right_sign", "effort_sign:=-1");
  EXPECT_GE(right.mean_return, 300.0);
  // ... against a fall within a few dozen steps when pushed the wrong way (8.8).
  const Verdict wrong = evaluate(home, "wrong_sign", "effort_sign:=1");
  EXPECT_EQ(0u, wrong.balanced);
  EXPECT_LT(wrong.mean_return, 100.0);
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robot_group_command_test");
  ros::NodeHandle nh;
  const int result = RUN_ALL_TESTS();
  const std::string home = privateParam("ros_home");
  if (!home.empty())
    std::filesystem::remove_all(home);
  return result;
}
