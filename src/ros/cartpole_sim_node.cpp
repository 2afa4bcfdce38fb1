// cartpole_sim: the simulated cart-pole robot (see ros/cartpole_sim.h).
#include "cartpole_qlearning/ros/cartpole_sim.h"
#include "start_up.h"

#include <memory>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "cartpole_sim");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::CartPoleSimNode> node;
  if (!cartpole_qlearning::startNode("cartpole_sim", ros::this_node::getName(),
                                     [&] { node = std::make_unique<cartpole_qlearning::CartPoleSimNode>(nh, pnh); }))
    return 1;
  ros::spin();
  return 0;
}
