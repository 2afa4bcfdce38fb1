// bare_pong: answers every sensor_msgs/JointState on ping_state with one command on
// ping_command, shaped as the controller's joint_command (a 1-joint JointState, cart_joint, one
// effort, stamped with the state's stamp, which bare_ping matches), and does nothing else: the
// cheapest possible controller, for bare_ping.
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

namespace
{
class BarePong
{
public:
  explicit BarePong(ros::NodeHandle& nh)
  {
    command_.name = {"cart_joint"};
    command_.effort = {0.0};
    command_pub_ = nh.advertise<sensor_msgs::JointState>("ping_command", 10);
    state_sub_ = nh.subscribe("ping_state", 10, &BarePong::onState, this, ros::TransportHints().tcpNoDelay());
  }

private:
  void onState(const sensor_msgs::JointStateConstPtr& msg)
  {
    command_.header.stamp = msg->header.stamp;
    command_.effort[0] = msg->effort.empty() ? 10.0 : -msg->effort[0];  // bang-bang, as the learner's actions
    command_pub_.publish(command_);
  }

  sensor_msgs::JointState command_;
  ros::Publisher command_pub_;
  ros::Subscriber state_sub_;
};
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "bare_pong");
  ros::NodeHandle nh;
  BarePong pong(nh);
  ros::spin();
  return 0;
}
