// A table trained by train_headless (our sim's sign and step) evaluated on the graph against the sim posing as
// another robot, through robot.launch mode:=evaluate as a user runs it (robot_group_command.test,
// robot_position_only.test). Private parameters: ros_home (ROS_HOME of train_headless and the launches), args (the
// robot.launch arguments for that robot), min_return (the mean return the evaluation must reach), and optionally
// wrong_args and max_return: the same evaluation with those arguments added (a setting of the robot left out) must
// stay below max_return, so that the first result is the setting's doing.
#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <limits>
#include <string>

using cartpole_qlearning::test::privateParam;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::TrainLaunch;
namespace text_match = cartpole_qlearning::test::text_match;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");
// A number the .test file must set: a missing one fails the test (NaN fails every comparison).
double numberParam(const std::string& name)
{
  double value = 0.0;
  if (!ros::param::get("~" + name, value))
  {
    ADD_FAILURE() << "~" << name << " is not set";
    return std::numeric_limits<double>::quiet_NaN();
  }
  return value;
}

// robot.launch mode:=evaluate with the table, 5 episodes, and `args`; the mean return of its verdict (-1: none).
double evaluate(const std::string& home, const std::string& name, const std::string& args)
{
  // The sim poses in lockstep and holds no command: no freshness guard.
  TrainLaunch launch(home, name, "mode:=evaluate load:=q_table.yaml episodes:=5 freshness_timeout:=0 " + args,
                     "robot.launch");
  const int status = launch.waitFor(90.0);
  const std::string output = launch.output();
  EXPECT_EQ(0, status) << output;
  text_match::Groups m;
  if (!text_match::contains(output,
                            "EVALUATED 5 episodes: [0-9]+ balanced to the step limit \\(500 steps\\), "
                            "mean return ([0-9.]+)",
                            &m))
  {
    ADD_FAILURE() << output;
    return -1.0;
  }
  std::printf("%s: %s\n", name.c_str(), m[0].c_str());
  return std::stod(m[1]);
}
}  // namespace

TEST(RobotEvaluate, TheHeadlessTableKeepsThePoleUpOnThePosedRobotAndNotWithoutItsSetting)
{
  const std::string home = kRosHome.path();
  ASSERT_FALSE(home.empty());
  std::filesystem::create_directories(home);
  const auto trained =
      runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --seed 0 --quiet --no-run-folder --save q_table.yaml");
  ASSERT_EQ(0, trained.status) << trained.output;
  ASSERT_EQ(0u, trained.lastLine().find("until=solved reached=true solved=true ")) << trained.output;

  const std::string args = privateParam("args");
  EXPECT_GE(evaluate(home, "posed", args), numberParam("min_return"));
  if (!privateParam("wrong_args").empty())
  {
    EXPECT_LT(evaluate(home, "setting_left_out", args + " " + privateParam("wrong_args")), numberParam("max_return"));
  }
}
