// qlearning_controller: the tabular Q-learning controller (see ros/qlearning_controller.h).
#include "cartpole_qlearning/ros/qlearning_controller.h"
#include "cartpole_qlearning/ros/start_up.h"

#include <memory>

int main(int argc, char** argv)
{
  ros::init(argc, argv, "qlearning_controller");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::QLearningControllerNode> node;
  if (!cartpole_qlearning::startNode("qlearning_controller", [&] {
        node = std::make_unique<cartpole_qlearning::QLearningControllerNode>(
            nh, pnh, [] { ros::shutdown(); }, true);
      }))
    return 1;
  ros::spin();
  return 0;
}
