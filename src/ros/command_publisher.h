// The controller's command to one robot, in the message type that robot takes (~command_type).
#pragma once

#include "cartpole_qlearning/protocol/robot_interface.h"

#include <ros/ros.h>

namespace cartpole_qlearning
{
class CommandPublisher
{
public:
  CommandPublisher() = default;
  // Advertises `topic` (relative to nh) with the type params.command_type says.
  CommandPublisher(ros::NodeHandle& nh, const std::string& topic, const RobotInterfaceParams& params);

  // The effort [N] (the task's sign: robotEffort turns it into the robot's), stamped with the state
  // it answers when the type has a stamp; it is held for hold().
  void publish(double effort, const ros::Time& stamp);
  // A state between two decisions (~decision_period): a stamped command answers it with the
  // effort held (a lockstep sim steps only on an answer); Float64 commands go out at decisions
  // only (the robot's controller holds the last one).
  // allowed false (the freshness guard): 0 in place of the effort held.
  void hold(const ros::Time& stamp, bool allowed = true)
  {
    if (params_.command_type == CommandType::JointState)
      publish(allowed ? held_ : 0.0, stamp);
  }
  // Zero effort, unstamped: it answers no state (a lockstep sim steps on no such command), it
  // stops a robot that holds its last command (ros_control's forward controllers hold it forever).
  void stop()
  {
    publish(0.0, ros::Time());
  }
  // A command another node wrote in this type, published as it came (command_watchdog).
  template <class Message>
  void forward(const boost::shared_ptr<const Message>& msg)
  {
    pub_.publish(msg);
  }

private:
  ros::Publisher pub_;
  RobotInterfaceParams params_;
  double held_ = 0.0;
};

}  // namespace cartpole_qlearning
