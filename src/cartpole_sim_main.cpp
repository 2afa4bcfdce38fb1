// cartpole_sim: the simulated cart-pole robot (see cartpole_sim_node.h).
#include "cartpole_qlearning/launch_control.h"
#include "cartpole_qlearning/cartpole_sim_node.h"
#include "cartpole_qlearning/config.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "cartpole_sim");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try
  {
    cartpole_qlearning::CartPoleSimNode node(nh, pnh);
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("cartpole_sim: %s", e.what());
    // Under roslaunch the node may respawn: it would fail the same way, forever. The launch
    // ends instead (a crash later on still respawns).
    if (cartpole_qlearning::endParentLaunch())
      ROS_FATAL("cartpole_sim: ending the launch: this cannot work until the above is fixed");
    return 1;
  }
  return 0;
}
