// cartpole_sim: the simulated cart-pole robot (see ros/cartpole_sim.h).
#include "cartpole_qlearning/ros/cartpole_sim.h"
#include "start_up.h"

#include <memory>

int main(int argc, char** argv)
{
  const bool check_only = cartpole_qlearning::takeCheckFlag(argc, argv);
  ros::init(argc, argv, "cartpole_sim");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::CartPoleSimNode> node;
  // A check constructs the node as a start does (its parameters, its engine and model) and ends:
  // it runs on a master of the check's own, where its topics reach nobody.
  if (!cartpole_qlearning::startNode(
          "cartpole_sim", ros::this_node::getName(),
          [&] { node = std::make_unique<cartpole_qlearning::CartPoleSimNode>(nh, pnh); }, nullptr, !check_only))
    return 1;
  if (check_only)
    return 0;
  ros::spin();
  return 0;
}
