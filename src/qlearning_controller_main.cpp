// qlearning_controller: the tabular Q-learning controller (see qlearning_controller_node.h).
#include "cartpole_qlearning/launch_control.h"
#include "cartpole_qlearning/qlearning_controller_node.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "qlearning_controller");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try
  {
    cartpole_qlearning::QLearningControllerNode node(
        nh, pnh, [] { ros::shutdown(); }, true);
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("qlearning_controller: %s", e.what());
    // Under roslaunch the node may respawn: it would fail the same way, forever. The launch
    // ends instead (a crash later on still respawns).
    if (cartpole_qlearning::endParentLaunch())
      ROS_FATAL("qlearning_controller: ending the launch: this cannot work until the above is fixed");
    return 1;
  }
  return 0;
}
