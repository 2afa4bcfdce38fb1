// qlearning_controller: the tabular Q-learning controller (see ros/qlearning_controller.h).
#include "cartpole_qlearning/ros/qlearning_controller.h"
#include "start_up.h"

#include <atomic>
#include <csignal>
#include <memory>

namespace
{
std::atomic<bool> g_stop_requested{false};

// Ctrl-C and roslaunch's kill (SIGINT, then SIGTERM): only noted here; main commands zero
// effort while ROS still runs, then shuts it down.
void requestStop(int)
{
  g_stop_requested = true;
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "qlearning_controller", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::QLearningControllerNode> node;
  if (!cartpole_qlearning::startNode("qlearning_controller", ros::this_node::getName(), [&] {
        node = std::make_unique<cartpole_qlearning::QLearningControllerNode>(
            nh, pnh, [] { ros::shutdown(); }, true);
      }))
    return 1;
  while (ros::ok() && !g_stop_requested)
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  if (g_stop_requested)
  {
    node->stop();
    // The zero goes out on the publishers' connections, which ros::shutdown closes.
    ros::WallDuration(0.2).sleep();
    ros::shutdown();
  }
  return 0;
}
