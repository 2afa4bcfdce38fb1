// command_watchdog: between the controller and a robot, forwards the controller's commands as they
// come and leaves the robot at 0 when they stop: no command for ~timeout while the robot may be
// pushed (a controller that hung, crashed or was killed by kill -9), the controller's publisher
// gone (it unregistered), a command that is no number, and the watchdog's own end (core: protocol/command_watchdog.h).
// The twist_mux / diff_drive_controller cmd_vel_timeout pattern, for robots that hold their last command for ever
// (ros_control's JointEffortController). It takes the commands in the robot's type (~command_type,
// as the controller writes them) on `controller_command` and publishes on ~command_topic (the
// robot's). Logs on ros.cartpole_qlearning.command_watchdog.<its name, dots for slashes>.
#pragma once

#include "cartpole_qlearning/protocol/command_watchdog.h"
#include "cartpole_qlearning/protocol/robot_interface.h"

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>

#include <memory>
#include <mutex>
#include <string>

namespace cartpole_qlearning
{
class CommandPublisher;

class CommandWatchdogNode
{
public:
  // nh: the namespace of the controller (its relative topics); pnh: the node's own parameters.
  // Throws ConfigError naming a parameter it refuses.
  CommandWatchdogNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);
  ~CommandWatchdogNode();
  CommandWatchdogNode(const CommandWatchdogNode&) = delete;
  CommandWatchdogNode& operator=(const CommandWatchdogNode&) = delete;

  // The watchdog is ending: 0 to the robot when it may be pushed. Call while ROS still runs, and
  // give the zero a moment to leave before the connections close.
  void stop();

private:
  void readParameters();
  template <class Message>
  void onCommand(const boost::shared_ptr<const Message>& msg);
  void onTick(const ros::WallTimerEvent&);
  void carryOut(CommandWatchdog::Action action);
  void say(const LogLines& log);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  std::string name_;
  RobotInterfaceParams robot_;
  double timeout_s_ = 0.1;
  std::mutex mutex_;  // the nodelet's callbacks may run on several threads
  CommandWatchdog watchdog_;
  std::unique_ptr<CommandPublisher> out_;
  ros::Subscriber in_;
  ros::WallTimer timer_;
};

}  // namespace cartpole_qlearning
