// robot.launch mode:=control as a robot owner runs it (control_robot.test): a table trained by
// train_headless --config config/robust.yaml drives the sim posing as a robot it never met for five
// minutes of the robot's time (lockstep: 15,000 decisions). What must hold: control_stats reports
// the time, the longest stretch and the falls, and they add up with what the log says; every
// fall is followed by a reset and control goes on; Ctrl-C ends it with a zero command and a last
// line that says how it went. How long the table keeps the pole up is printed, not asserted: a
// table robust.yaml trains until it passes the one-minute suite (all_at_once 95 of 100) can
// still fall in five minutes of all_at_once (docs/robust_tables.md). The seed is the .test's
// `seed` argument (default 0): rostest cartpole_qlearning control_robot.test seed:=3; the robot is
// the suite case the sim poses as (`suite`, `suite_case`; default all_at_once); `predict_delay`
// is robot.launch's (default 1: the posed robot answers a step late; give 0 for a case without a
// delay, which a prediction drops).
#include "cartpole_qlearning/ControlStats.h"

#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/UInt32.h>

#include <filesystem>
#include <mutex>
#include <string>

using cartpole_qlearning::ControlStats;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::spinUntil;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");

std::size_t occurrences(const std::string& text, const std::string& what)
{
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}
}  // namespace

TEST(ControlRobot, ATableDrivesAPosedRobotForFiveMinutesOfItsTimeAndCtrlCLeavesZero)
{
  const std::string home = kRosHome.path();
  ASSERT_FALSE(home.empty());
  std::filesystem::create_directories(home);
  int seed = 0;
  ros::param::get("~seed", seed);
  std::string suite_case = "all_at_once";
  ros::param::get("~suite_case", suite_case);
  // -1: not told (robot.launch's default): the controller finds the delay, which must be found_delay.
  int predict_delay = 0;
  ros::param::get("~predict_delay", predict_delay);
  int found_delay = 1;
  ros::param::get("~found_delay", found_delay);
  // The config that trains the table (robust.yaml, or robust_five_minutes.yaml: config:=).
  std::string config = std::string(CARTPOLE_CONFIG_DIR) + "/robust.yaml";
  ros::param::get("~config", config);
  // average_with:=K: the table run is the mean of seed's and seed K's (train_headless --average).
  int average_with = -1;
  ros::param::get("~average_with", average_with);
  const auto train = [&](int table_seed, const std::string& path) {
    return runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --config " + config + " --seed " +
                      std::to_string(table_seed) + " --quiet --no-run-folder --save " + path);
  };
  const auto trained = train(seed, average_with < 0 ? "robust.yaml" : "first.yaml");
  ASSERT_EQ(0, trained.status) << trained.output;
  if (average_with >= 0)
  {
    const auto second = train(average_with, "second.yaml");
    ASSERT_EQ(0, second.status) << second.output;
    const auto mean = runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS +
                                 " --average first.yaml --average second.yaml --save robust.yaml");
    ASSERT_EQ(0, mean.status) << mean.output;
  }

  ros::NodeHandle nh;
  ControlStats last;
  int reports = 0;
  double last_effort = -1.0;
  int commands = 0;
  const ros::Subscriber stats =
      nh.subscribe<ControlStats>("/cartpole/control_stats", 1000,
                                 boost::function<void(const cartpole_qlearning::ControlStatsConstPtr&)>(
                                     [&](const cartpole_qlearning::ControlStatsConstPtr& m) {
                                       last = *m;
                                       ++reports;
                                     }));
  int published_delay = -1;
  const ros::Subscriber delay = nh.subscribe<std_msgs::UInt32>(
      "/cartpole/qlearning_controller/found_delay_steps", 10,
      boost::function<void(const std_msgs::UInt32ConstPtr&)>(
          [&](const std_msgs::UInt32ConstPtr& m) { published_delay = static_cast<int>(m->data); }));
  const ros::Subscriber command = nh.subscribe<sensor_msgs::JointState>(
      "/cartpole/joint_command", 1000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        if (!m->effort.empty())
          last_effort = m->effort[0];
        ++commands;
      }));

  // The sim holds no command in lockstep: no freshness guard. A report each minute of robot time;
  // the motor's limit is the table's 10 N, as the robot's owner gives it.
  TrainLaunch launch(home, "control",
                     "mode:=control load:=robust.yaml robot_lockstep:=true max_effort:=10 "
                     "reset_service:=cartpole_sim/reset "
                     "report_every:=60" +
                         (predict_delay < 0 ? std::string() : " predict_delay:=" + std::to_string(predict_delay)),
                     "robot.launch");
  ASSERT_TRUE(spinUntil([&] { return last.seconds >= 300.0; }, 300.0))
      << reports << " reports, the last at " << last.seconds << " s\n"
      << launch.output();
  const ControlStats at_five_minutes = last;
  EXPECT_EQ(0, launch.interrupt(30.0)) << launch.output();
  spinUntil([&] { return false; }, 0.5);  // what was sent before the end arrives
  const std::string output = launch.output();

  // The stats add up: robot time is decisions times the step, balanced time within it, the
  // longest stretch within that; every fall was said, and every minute reported.
  // The robot's time is its stamps: a step a decision, and one more per reset (a reset takes a
  // step of sim time), the first decision starting the clock.
  EXPECT_NEAR(at_five_minutes.decisions * 0.02, at_five_minutes.seconds, 0.02 * (at_five_minutes.falls + 1) + 1e-6);
  EXPECT_LE(at_five_minutes.balanced_seconds, at_five_minutes.seconds);
  EXPECT_LE(at_five_minutes.longest_seconds, at_five_minutes.balanced_seconds + 1e-9);
  EXPECT_LE(at_five_minutes.current_seconds, at_five_minutes.longest_seconds + 1e-9);
  EXPECT_EQ(last.falls, occurrences(output, "the pole fell after")) << output;
  EXPECT_GE(occurrences(output, "control: balanced "), 4u) << output;
  // Control went on after each fall (the reset service put the pole back): most of the time is balanced.
  EXPECT_GT(at_five_minutes.balanced_seconds, 0.9 * at_five_minutes.seconds);
  // Ctrl-C: zero effort last, and the last line says how it went.
  EXPECT_GT(commands, 0);
  EXPECT_EQ(0.0, last_effort);
  EXPECT_TRUE(cartpole_qlearning::test::text_match::contains(
      output,
      "control ended: balanced [0-9.]+ s of [0-9.]+ s, the longest stretch [0-9.]+ s, [0-9]+ falls?, 0 of "
      "[0-9]+ commands beyond the motor's 10 N"))
      << output;
  // robot.launch predict_delay:=N reached the controller, which says so as it starts.
  if (predict_delay > 0)
    EXPECT_TRUE(cartpole_qlearning::test::text_match::contains(
        output, "deciding for the state predicted " + std::to_string(predict_delay) + " steps? ahead"))
        << output;
  else if (predict_delay == 0)
    EXPECT_EQ(std::string::npos, output.find("deciding for the state predicted")) << output;
  else
  {
    // Not told: found from the states, said once and published (latched).
    EXPECT_EQ(1u, occurrences(output, "carries out each command " + std::to_string(found_delay) +
                                          (found_delay == 1 ? " step" : " steps") + " late"))
        << output;
    EXPECT_EQ(1u, occurrences(output, "carries out each command")) << "another delay was said:\n" << output;
    EXPECT_EQ(found_delay, published_delay);
  }
  const std::string table = average_with < 0 ? "seed " + std::to_string(seed) + "'s table"
                                             : "the mean of seeds " + std::to_string(seed) + " and " +
                                                   std::to_string(average_with) + "'s tables";
  std::printf(
      "five minutes of control on %s, %s, predict_delay %d: %.1f s balanced, the longest "
      "stretch %.1f s, %llu falls\n",
      suite_case.c_str(), table.c_str(), predict_delay, at_five_minutes.balanced_seconds,
      at_five_minutes.longest_seconds, static_cast<unsigned long long>(at_five_minutes.falls));
}
