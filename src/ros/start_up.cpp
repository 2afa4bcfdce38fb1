#include "cartpole_qlearning/ros/start_up.h"

#include "cartpole_qlearning/ros/launch_control.h"

#include <ros/console.h>

#include <exception>

namespace cartpole_qlearning
{
bool startNode(const std::string& name, const std::function<void()>& start, std::string* reason)
{
  // Only the start-up is caught here: an exception from a callback later is a crash like any
  // other, and under train.launch the node respawns.
  try
  {
    start();
    return true;
  }
  catch (const std::exception& e)
  {
    // ros.cartpole_qlearning.<name>: the logger the node logs on afterwards.
    ROS_FATAL_STREAM_NAMED(name, name << ": " << e.what());
    if (endParentLaunch())
      ROS_FATAL_STREAM_NAMED(name, name << ": ending the launch: this cannot work until the above is fixed");
    if (reason != nullptr)
      *reason = e.what();
    return false;
  }
}

}  // namespace cartpole_qlearning
