// bare_pong: answers every sensor_msgs/JointState on ping_state with one std_msgs/Float64 on
// ping_answer (its position[0], which bare_ping uses as a sequence number), and does nothing
// else: the cheapest possible controller, for bare_ping.
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

namespace
{
class BarePong
{
public:
  explicit BarePong(ros::NodeHandle& nh)
  {
    answer_pub_ = nh.advertise<std_msgs::Float64>("ping_answer", 10);
    state_sub_ = nh.subscribe("ping_state", 10, &BarePong::onState, this, ros::TransportHints().tcpNoDelay());
  }

private:
  void onState(const sensor_msgs::JointStateConstPtr& msg)
  {
    std_msgs::Float64 answer;
    answer.data = msg->position.empty() ? 0.0 : msg->position[0];
    answer_pub_.publish(answer);
  }

  ros::Publisher answer_pub_;
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
