// cartpole_sim: the simulated cart-pole robot (see cartpole_sim_node.h).
#include "cartpole_qlearning/launch_control.h"
#include "cartpole_qlearning/cartpole_sim_node.h"
#include "cartpole_qlearning/config.h"

#include <memory>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "cartpole_sim");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  // Only the start-up is caught here: an exception from a callback later is a crash like any
  // other, and under train.launch the node respawns.
  std::unique_ptr<cartpole_qlearning::CartPoleSimNode> node;
  try
  {
    node = std::make_unique<cartpole_qlearning::CartPoleSimNode>(nh, pnh);
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("cartpole_sim: %s", e.what());
    // Under roslaunch the node may respawn: it would fail the same way, forever. The launch
    // ends instead.
    if (cartpole_qlearning::endParentLaunch())
      ROS_FATAL("cartpole_sim: ending the launch: this cannot work until the above is fixed");
    return 1;
  }
  ros::spin();
  return 0;
}
