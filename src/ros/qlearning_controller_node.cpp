// qlearning_controller: the tabular Q-learning controller (see ros/qlearning_controller.h).
#include "cartpole_qlearning/ros/qlearning_controller.h"
#include "start_up.h"

#include <memory>

int main(int argc, char** argv)
{
  const bool check_only = cartpole_qlearning::takeCheckFlag(argc, argv);
  ros::init(argc, argv, "qlearning_controller", ros::init_options::NoSigintHandler);
  // Ctrl-C and roslaunch's kill: the controller commands zero effort while ROS still runs.
  cartpole_qlearning::noteStopSignals();
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::QLearningControllerNode> node;
  if (!cartpole_qlearning::startNode(
          "qlearning_controller", ros::this_node::getName(),
          [&] {
            if (check_only)
              cartpole_qlearning::QLearningControllerNode::checkParameters(nh, pnh);
            else
              node = std::make_unique<cartpole_qlearning::QLearningControllerNode>(
                  nh, pnh, [] { ros::shutdown(); }, true);
          },
          nullptr, !check_only))
    return 1;
  if (check_only)
    return 0;
  // A training run that finished has shut ROS down itself: nothing to stop then.
  cartpole_qlearning::spinUntilStopped(0.05, false, [&] { node->stop(); });
  return 0;
}
