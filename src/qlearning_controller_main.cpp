// qlearning_controller: the tabular Q-learning controller (see qlearning_controller_node.h).
#include "cartpole_qlearning/launch_control.h"
#include "cartpole_qlearning/qlearning_controller_node.h"

#include <memory>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "qlearning_controller");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  // Only the start-up is caught here: an exception from a callback later is a crash like any
  // other, and under train.launch the node respawns.
  std::unique_ptr<cartpole_qlearning::QLearningControllerNode> node;
  try
  {
    node = std::make_unique<cartpole_qlearning::QLearningControllerNode>(
        nh, pnh, [] { ros::shutdown(); }, true);
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("qlearning_controller: %s", e.what());
    // Under roslaunch the node may respawn: it would fail the same way, forever. The launch
    // ends instead.
    if (cartpole_qlearning::endParentLaunch())
      ROS_FATAL("qlearning_controller: ending the launch: this cannot work until the above is fixed");
    return 1;
  }
  ros::spin();
  return 0;
}
