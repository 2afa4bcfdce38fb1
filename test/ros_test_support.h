// Helpers the rostest test nodes share.
#pragma once

#include <ros/ros.h>

#include <functional>

namespace cartpole_qlearning
{
namespace test
{
// Spins the global callback queue until done() holds or the wall-clock timeout passes (wall
// clock: in lockstep, ROS time is the sim's and may stand still).
inline bool spinUntil(const std::function<bool()>& done, double timeout_s)
{
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    if (done())
      return true;
    ros::WallDuration(0.001).sleep();
  }
  ros::spinOnce();
  return done();
}

}  // namespace test
}  // namespace cartpole_qlearning
