// The command watchdog (command_watchdog.test): kill -9 of the controller during robot.launch
// mode:=control leaves 0 on the robot's command topic within 0.2 s, as the robot sees it, for a
// JointState robot and a Float64 one (ros_control's JointEffortController, which holds the last
// command for ever); and the watchdog alone, fed by this test, in each command type: commands
// forwarded as they came, 0 when they stop, when their publisher goes and when it ends.
#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <signal.h>

using cartpole_qlearning::test::ChildProcess;
using cartpole_qlearning::test::pidOf;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::spinUntil;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");
const char* const kController = "/cartpole/qlearning_controller";

// What arrives on a command topic: each effort with the wall time it arrived.
struct Arrivals
{
  std::vector<std::pair<ros::WallTime, double>> seen;

  void add(double effort)
  {
    seen.emplace_back(ros::WallTime::now(), effort);
  }
  std::size_t pushes() const
  {
    std::size_t n = 0;
    for (const auto& [at, effort] : seen)
      n += effort != 0.0 ? 1 : 0;
    return n;
  }
  // The first 0 that arrived after `t`, or none.
  std::optional<ros::WallTime> zeroAfter(const ros::WallTime& t) const
  {
    for (const auto& [at, effort] : seen)
      if (at >= t && effort == 0.0)
        return at;
    return std::nullopt;
  }
};

std::string trainedTable(const std::string& home)
{
  std::filesystem::create_directories(home);
  const std::string table = home + "/balancing.yaml";
  if (!std::filesystem::exists(table))
  {
    const auto trained = runCommand(std::string(TRAIN_HEADLESS) + " --config " + CARTPOLE_CONFIG_DIR +
                                    "/cartpole.yaml --seed 0 --quiet --no-run-folder --save " + table);
    EXPECT_EQ(0, trained.status) << trained.output;
  }
  return table;
}

// robot.launch mode:=control on the sim (its reset after a fall, so the table keeps pushing); once
// the robot has had 50 pushes, kill -9 of the controller right after a push: the seconds until
// the robot's topic got 0 (printed), and the launch ends (its controller is required).
double killToZero(const std::string& name, const std::string& args, Arrivals& arrivals)
{
  const std::string home = kRosHome.path();
  const std::string table = trainedTable(home);
  TrainLaunch launch(home, name, "mode:=control load:=" + table + " reset_service:=cartpole_sim/reset " + args,
                     "robot.launch");
  EXPECT_TRUE(spinUntil([&] { return arrivals.pushes() >= 50; }, 60.0)) << launch.output();
  // Right after a push: the robot holds it, and nothing else would take it back.
  const std::size_t before = arrivals.seen.size();
  EXPECT_TRUE(spinUntil([&] { return arrivals.seen.size() > before && arrivals.seen.back().second != 0.0; }, 10.0));
  const int pid = pidOf(kController);
  EXPECT_GT(pid, 0);
  if (pid <= 0)
    return -1.0;
  ::kill(pid, SIGKILL);
  const ros::WallTime killed = ros::WallTime::now();
  spinUntil([&] { return arrivals.zeroAfter(killed).has_value(); }, 5.0);
  const std::optional<ros::WallTime> zero = arrivals.zeroAfter(killed);
  EXPECT_TRUE(zero.has_value()) << launch.output();
  // Nothing pushes the robot after that zero (a command the dead controller had sent is dropped).
  spinUntil([] { return false; }, 1.0);
  EXPECT_EQ(0.0, arrivals.seen.back().second) << launch.output();
  // Its controller required: the launch ends by itself, the watchdog's zero given.
  EXPECT_GE(launch.waitFor(60.0), 0) << "the launch did not end after its controller died\n" << launch.output();
  const std::string output = launch.output();
  EXPECT_NE(std::string::npos, output.find("REQUIRED process [cartpole/qlearning_controller")) << output;
  if (!zero)
    return -1.0;
  const double seconds = (*zero - killed).toSec();
  std::printf("%s: kill -9 of the controller to 0 on the robot's command topic: %.3f s\n", name.c_str(), seconds);
  std::fflush(stdout);
  return seconds;
}
}  // namespace

TEST(CommandWatchdog, KillMinus9OfTheControllerLeavesAJointStateRobotAtZeroWithin200Ms)
{
  ros::NodeHandle nh;
  Arrivals arrivals;
  const ros::Subscriber sub = nh.subscribe<sensor_msgs::JointState>(
      "/cartpole/joint_command", 1000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        arrivals.add(m->effort.empty() ? std::nan("") : m->effort[0]);
      }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  const double seconds = killToZero("joint_state", "", arrivals);
  EXPECT_GE(seconds, 0.0);
  EXPECT_LE(seconds, 0.2);
}

TEST(CommandWatchdog, KillMinus9OfTheControllerLeavesAFloat64RobotAtAFloat64ZeroWithin200Ms)
{
  ros::NodeHandle nh;
  Arrivals arrivals;
  const ros::Subscriber sub =
      nh.subscribe<std_msgs::Float64>("/cartpole/cart_effort", 1000,
                                      boost::function<void(const std_msgs::Float64ConstPtr&)>(
                                          [&](const std_msgs::Float64ConstPtr& m) { arrivals.add(m->data); }),
                                      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  const double seconds = killToZero("float64", "command_type:=float64 joint_command:=cart_effort", arrivals);
  EXPECT_GE(seconds, 0.0);
  EXPECT_LE(seconds, 0.2);
}

// The watchdog alone in /alone_<type>, fed by this test: Float64, Float64MultiArray and JointState
// commands forwarded as they came; 0 after the timeout, when the publisher goes, and at its end.
template <class Message>
void watchdogAlone(const std::string& type, const std::function<Message(double)>& make,
                   const std::function<double(const Message&)>& effort)
{
  const std::string ns = "/alone_" + type;
  ros::param::set(ns + "/command_watchdog/command_type", type);
  ros::param::set(ns + "/command_watchdog/command_topic", "robot_command");
  // 0.3 s, fifteen times the 20 ms between this test's commands: a sanitized build beside other
  // work on two cores stalled the watchdog more than 0.1 s between two of them once.
  ros::param::set(ns + "/command_watchdog/timeout", 0.3);
  if (type == "float64_array")
  {
    ros::param::set(ns + "/command_watchdog/command_index", 1);
    ros::param::set(ns + "/command_watchdog/command_size", 3);
  }
  ros::NodeHandle nh;
  std::vector<double> got;
  const ros::Subscriber sub = nh.subscribe<Message>(ns + "/robot_command", 100,
                                                    boost::function<void(const boost::shared_ptr<const Message>&)>(
                                                        [&](const auto& m) { got.push_back(effort(*m)); }));
  ChildProcess watchdog(COMMAND_WATCHDOG, {"__ns:=" + ns});
  auto pub = std::make_unique<ros::Publisher>(nh.advertise<Message>(ns + "/command_watchdog/controller_command", 10));
  ASSERT_TRUE(spinUntil([&] { return pub->getNumSubscribers() > 0 && sub.getNumPublishers() > 0; }, 20.0));
  // The subscriber counts the watchdog's link before its handshake has ended, and what the
  // watchdog forwards meanwhile is lost (a sanitized Debian 11 run under load lost the first of
  // the ten commands below): a probe every 50 ms until one comes through, then its timeout's 0.
  ros::WallTime probed;
  const auto came_through = [&] { return std::any_of(got.begin(), got.end(), [](double e) { return e != 0.0; }); };
  ASSERT_TRUE(spinUntil(
      [&] {
        if (!came_through() && ros::WallTime::now() - probed > ros::WallDuration(0.05))
        {
          pub->publish(make(1.0));
          probed = ros::WallTime::now();
        }
        return came_through();
      },
      20.0));
  ASSERT_TRUE(spinUntil([&] { return got.back() == 0.0; }, 20.0));
  got.clear();

  // Forwarded as they came, then a gap: 0 once. A 0 between two commands is the watchdog doing its
  // job after a stall longer than its timeout (counted, printed), never a command lost or reordered.
  const auto pushes = [&] {
    std::vector<double> nonzero;
    for (double e : got)
      if (e != 0.0)
        nonzero.push_back(e);
    return nonzero;
  };
  std::vector<double> sent;
  for (int i = 0; i < 10; ++i)
  {
    sent.push_back(i % 2 == 0 ? 7.0 : -7.0);
    pub->publish(make(sent.back()));
    spinUntil([] { return false; }, 0.02);
  }
  ASSERT_TRUE(spinUntil([&] { return pushes().size() >= sent.size() && got.back() == 0.0; }, 5.0)) << got.size();
  EXPECT_EQ(sent, pushes());
  const std::size_t stalls = got.size() - sent.size() - 1;
  if (stalls > 0)
    std::printf("%s: %zu zero(s) between commands 20 ms apart (a stall over the timeout)\n", type.c_str(), stalls);
  const std::size_t after_gap = got.size();
  spinUntil([] { return false; }, 1.0);
  EXPECT_EQ(after_gap, got.size()) << "one zero, not one per tick";

  // Pushing again, then the publisher goes (its node unregisters it, as a controller that ends does).
  pub->publish(make(5.0));
  ASSERT_TRUE(spinUntil([&] { return got.size() == after_gap + 1; }, 5.0));
  EXPECT_EQ(5.0, got.back());
  pub.reset();
  ASSERT_TRUE(spinUntil([&] { return got.size() == after_gap + 2; }, 5.0));
  EXPECT_EQ(0.0, got.back());

  // A new publisher pushing, then the watchdog's own end (Ctrl-C): 0.
  pub = std::make_unique<ros::Publisher>(nh.advertise<Message>(ns + "/command_watchdog/controller_command", 10));
  ASSERT_TRUE(spinUntil([&] { return pub->getNumSubscribers() > 0; }, 20.0));
  // Commands every 20 ms until the watchdog is told to end, so the timeout never fires first.
  std::size_t at_end = 0;
  for (int i = 0; i < 10; ++i)
  {
    pub->publish(make(3.0));
    spinUntil([] { return false; }, 0.02);
  }
  at_end = got.size();
  ASSERT_GT(at_end, after_gap + 2);
  EXPECT_EQ(3.0, got.back());
  ::kill(watchdog.pid(), SIGINT);
  pub->publish(make(3.0));
  ASSERT_TRUE(spinUntil([&] { return !got.empty() && got.back() == 0.0; }, 5.0));
  EXPECT_EQ(0, watchdog.wait());
}

TEST(CommandWatchdog, AloneItForwardsAndStopsFloat64Commands)
{
  watchdogAlone<std_msgs::Float64>(
      "float64",
      [](double e) {
        std_msgs::Float64 m;
        m.data = e;
        return m;
      },
      [](const std_msgs::Float64& m) { return m.data; });
}

TEST(CommandWatchdog, AloneItForwardsAndStopsFloat64ArrayCommands)
{
  watchdogAlone<std_msgs::Float64MultiArray>(
      "float64_array",
      [](double e) {
        std_msgs::Float64MultiArray m;
        m.data = {0.0, e, 0.0};
        return m;
      },
      [](const std_msgs::Float64MultiArray& m) { return m.data.size() == 3 ? m.data[1] : std::nan(""); });
}

TEST(CommandWatchdog, AloneItForwardsAndStopsJointStateCommands)
{
  watchdogAlone<sensor_msgs::JointState>(
      "joint_state",
      [](double e) {
        sensor_msgs::JointState m;
        m.name = {"cart_joint"};
        m.effort = {e};
        return m;
      },
      [](const sensor_msgs::JointState& m) { return m.effort.size() == 1 ? m.effort[0] : std::nan(""); });
}
