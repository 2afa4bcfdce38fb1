// What a launch takes (launch_inputs.test): only what it is given, and a parameter a node refuses
// ends it. Leftovers on the master do not count: `rosparam set` of fall thresholds
// of 60 degrees and of stray keys in the namespace robot.launch runs in, then robot.launch
// mode:=control with a table trained with config/cartpole.yaml (12 degrees). The test plays the
// robot: upright, the table pushes; the pole at 20 degrees, past the table's 12 but within the
// leftovers' 60, the controller commands 0 (a fall), as it does on a clean master. A refused
// parameter (a table that is not there, a value out of range) ends evaluate.launch, train.launch and
// robot.launch before any node starts, the [FATAL] line naming it, with exit status 1 (the launch's
// check, scripts/check_launch); without the check (check_parameters:=false) the node refuses it when
// it starts and still ends the launch (then roslaunch 1.15's exit status is 0 whatever its nodes
// did: docs/troubleshooting.md).
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");
constexpr double kDegree = M_PI / 180.0;

// joint_states at 50 Hz with the pole at `theta` (still), for `seconds`; the commands that came
// meanwhile, after the first `settle` seconds.
std::vector<double> holdPole(ros::Publisher& states, std::vector<double>& commands, double theta, double seconds,
                             double settle)
{
  const ros::WallTime start = ros::WallTime::now();
  std::size_t from = commands.size();
  bool settled = false;
  ros::WallRate rate(50.0);
  while (ros::ok() && (ros::WallTime::now() - start).toSec() < seconds)
  {
    if (!settled && (ros::WallTime::now() - start).toSec() >= settle)
    {
      from = commands.size();
      settled = true;
    }
    sensor_msgs::JointState msg;
    msg.header.stamp = ros::Time::now();
    msg.name = {"cart_joint", "pole_joint"};
    msg.position = {0.0, theta};
    msg.velocity = {0.0, 0.0};
    states.publish(msg);
    ros::spinOnce();
    rate.sleep();
  }
  ros::spinOnce();
  return {commands.begin() + static_cast<std::ptrdiff_t>(std::min(from, commands.size())), commands.end()};
}
}  // namespace

TEST(LaunchLeftovers, RobotLaunchRunsTheTablesOwnConfigurationWhateverTheMasterHolds)
{
  const std::string home = kRosHome.path();
  ASSERT_FALSE(home.empty());
  std::filesystem::create_directories(home);
  const std::string table = home + "/balancing.yaml";
  const auto trained = runCommand(std::string(TRAIN_HEADLESS) + " --config " + CARTPOLE_CONFIG_DIR +
                                  "/cartpole.yaml --seed 0 --quiet --no-run-folder --save " + table);
  ASSERT_EQ(0, trained.status) << trained.output;

  // What an earlier launch, or a user, left: a config's thresholds at 60 degrees, keys no config has.
  ros::param::set("/cartpole/task/theta_threshold_deg", 60.0);
  ros::param::set("/cartpole/task/x_threshold", 20.0);
  ros::param::set("/cartpole/task/stray_key", 1.0);
  ros::param::set("/cartpole/stray_section/stray_key", "left over");
  ros::param::set("/cartpole/config_file", "/nowhere/left_over.yaml");

  ros::NodeHandle nh;
  std::vector<double> commands;
  const ros::Subscriber sub = nh.subscribe<sensor_msgs::JointState>(
      "/cartpole/joint_command", 1000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        if (!m->effort.empty())
          commands.push_back(m->effort[0]);
      }));
  ros::Publisher states = nh.advertise<sensor_msgs::JointState>("/cartpole/joint_states", 10);

  TrainLaunch launch(home, "control", "mode:=control load:=" + table, "robot.launch");
  // Upright until the controller acts on it: the table pushes.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(60.0);
  std::vector<double> upright;
  while (ros::ok() && ros::WallTime::now() < deadline && upright.size() < 20)
  {
    const std::vector<double> more = holdPole(states, commands, 0.0, 0.5, 0.0);
    for (double c : more)
      if (c != 0.0)
        upright.push_back(c);
  }
  ASSERT_GE(upright.size(), 20u) << "the controller never pushed an upright pole\n" << launch.output();

  // 20 degrees: past the table's 12, within the leftovers' 60. A fall: 0, and 0 while it lasts.
  const std::vector<double> tilted = holdPole(states, commands, 20.0 * kDegree, 2.0, 0.1);
  ASSERT_GE(tilted.size(), 10u) << launch.output();
  std::size_t pushes = 0;
  for (double c : tilted)
    pushes += c != 0.0 ? 1 : 0;
  EXPECT_EQ(0u, pushes) << "of " << tilted.size() << " commands for a pole at 20 degrees\n" << launch.output();
  const std::string output = launch.output();
  EXPECT_NE(std::string::npos, output.find("the table's own configuration (" + table + ")")) << output;

  // What the master holds now is the launch's: the leftovers are gone.
  double threshold = 0.0;
  EXPECT_FALSE(ros::param::get("/cartpole/task/theta_threshold_deg", threshold)) << threshold;
  EXPECT_FALSE(ros::param::has("/cartpole/stray_section"));
  EXPECT_FALSE(ros::param::has("/cartpole/config_file"));
  EXPECT_EQ(0, launch.interrupt(30.0)) << launch.output();
}

TEST(LaunchInputs, ARefusedParameterEndsEachLaunchNamingIt)
{
  const std::string home = kRosHome.path() + "/refusals";
  std::filesystem::create_directories(home);
  struct Case
  {
    const char* launch_file;
    const char* args;
    const char* names;
  };
  int n = 0;
  for (const Case& c :
       {Case{"evaluate.launch", "ns:=refused_evaluate q_table:=nope.yaml", "cannot start from the table 'nope.yaml'"},
        Case{"train.launch", "ns:=refused_train max_episodes:=-3", "max_episodes = -3 is not allowed"},
        Case{"robot.launch", "ns:=refused_robot decision_period:=20", "decision_period = 20 is not allowed"},
        Case{"robot.launch", "ns:=refused_watchdog watchdog_timeout:=5", "timeout = 5 is not allowed"}})
  {
    for (const bool checked : {true, false})
    {
      const std::string args = std::string(c.args) + (checked ? "" : " check_parameters:=false");
      TrainLaunch launch(home, "refused_" + std::to_string(n++), args, c.launch_file);
      const int status = launch.waitFor(60.0);
      const std::string output = launch.output();
      EXPECT_GE(status, 0) << c.launch_file << " " << args << " did not end by itself:\n" << output;
      EXPECT_NE(std::string::npos, output.find(c.names)) << output;
      EXPECT_NE(std::string::npos, output.find("[FATAL]")) << output;
      if (checked)
      {
        EXPECT_EQ(1, status) << c.launch_file << " " << args << ": a script cannot tell the launch failed\n" << output;
        EXPECT_NE(std::string::npos, output.find("nothing was started")) << output;
        EXPECT_EQ(std::string::npos, output.find("started with pid")) << "a node started:\n" << output;
      }
      std::printf("roslaunch cartpole_qlearning %s %s: ended, exit status %d\n", c.launch_file, args.c_str(), status);
    }
  }
}
