#include "command_publisher.h"

#include "cartpole_qlearning/ros/conversions.h"

namespace cartpole_qlearning
{
CommandPublisher::CommandPublisher(ros::NodeHandle& nh, const std::string& topic, const RobotInterfaceParams& params)
  : params_(params)
{
  switch (params.command_type)
  {
    case CommandType::JointState:
      pub_ = nh.advertise<sensor_msgs::JointState>(topic, 10);
      break;
    case CommandType::Float64:
      pub_ = nh.advertise<std_msgs::Float64>(topic, 10);
      break;
    case CommandType::Float64Array:
      pub_ = nh.advertise<std_msgs::Float64MultiArray>(topic, 10);
      break;
  }
}

void CommandPublisher::publish(double effort, const ros::Time& stamp)
{
  held_ = effort;
  const double out = robotEffort(params_, effort);
  // A new message each time: in a nodelet manager the subscriber receives this very pointer.
  switch (params_.command_type)
  {
    case CommandType::JointState:
      pub_.publish(boost::make_shared<sensor_msgs::JointState>(commandMessage(out, stamp, params_.command_joint)));
      break;
    case CommandType::Float64:
      pub_.publish(boost::make_shared<std_msgs::Float64>(float64Command(out)));
      break;
    case CommandType::Float64Array:
      pub_.publish(boost::make_shared<std_msgs::Float64MultiArray>(
          float64ArrayCommand(out, params_.command_index, params_.command_size)));
      break;
  }
}

}  // namespace cartpole_qlearning
