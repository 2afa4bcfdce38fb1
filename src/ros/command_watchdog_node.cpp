// command_watchdog: between the controller and the robot (see ros/command_watchdog.h).
#include "cartpole_qlearning/ros/command_watchdog.h"
#include "start_up.h"

#include <ros/callback_queue.h>

#include <atomic>
#include <csignal>
#include <memory>

namespace
{
std::atomic<bool> g_stop_requested{false};

// Ctrl-C and roslaunch's kill (SIGINT, then SIGTERM; also when a required controller died): only
// noted here; main sends the robot 0 while ROS still runs, then shuts it down.
void requestStop(int)
{
  g_stop_requested = true;
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "command_watchdog", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::CommandWatchdogNode> node;
  if (!cartpole_qlearning::startNode("command_watchdog", ros::this_node::getName(), [&] {
        node = std::make_unique<cartpole_qlearning::CommandWatchdogNode>(nh, pnh);
      }))
    return 1;
  while (ros::ok() && !g_stop_requested)
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
  node->stop();
  // The zero goes out on the publisher's connections, which ros::shutdown closes.
  ros::WallDuration(0.2).sleep();
  ros::shutdown();
  return 0;
}
