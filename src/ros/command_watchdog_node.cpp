// command_watchdog: between the controller and the robot (see ros/command_watchdog.h).
#include "cartpole_qlearning/ros/command_watchdog.h"
#include "start_up.h"

#include <memory>

int main(int argc, char** argv)
{
  const bool check_only = cartpole_qlearning::takeCheckFlag(argc, argv);
  ros::init(argc, argv, "command_watchdog", ros::init_options::NoSigintHandler);
  // Ctrl-C and roslaunch's kill (also when a required controller died): the watchdog sends the
  // robot 0 while ROS still runs.
  cartpole_qlearning::noteStopSignals();
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<cartpole_qlearning::CommandWatchdogNode> node;
  // A check constructs the node as a start does and ends (on a master of the check's own).
  if (!cartpole_qlearning::startNode(
          "command_watchdog", ros::this_node::getName(),
          [&] { node = std::make_unique<cartpole_qlearning::CommandWatchdogNode>(nh, pnh); }, nullptr, !check_only))
    return 1;
  if (check_only)
    return 0;
  cartpole_qlearning::spinUntilStopped(0.01, true, [&] { node->stop(); });
  return 0;
}
