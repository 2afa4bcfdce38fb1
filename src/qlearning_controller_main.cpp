// qlearning_controller: the tabular Q-learning controller (see qlearning_controller_node.h).
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
    return 1;
  }
  return 0;
}
