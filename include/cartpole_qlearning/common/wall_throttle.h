// Rate-limits a log message in wall-clock time. ROS_*_THROTTLE counts ros::Time, which is sim
// time in lockstep, where it runs about a hundred times faster than the wall clock.
#pragma once

#include <chrono>

namespace cartpole_qlearning
{
class WallThrottle
{
public:
  explicit WallThrottle(double period_s) : period_(period_s) {}

  // True at most once per period: the caller logs then.
  bool ready()
  {
    return ready(std::chrono::steady_clock::now());
  }
  // The same, at a time the caller gives (a clock injected in tests).
  bool ready(std::chrono::steady_clock::time_point now)
  {
    if (fired_ && now - last_ < period_)
      return false;
    fired_ = true;
    last_ = now;
    return true;
  }

private:
  std::chrono::duration<double> period_;
  std::chrono::steady_clock::time_point last_;
  bool fired_ = false;
};

}  // namespace cartpole_qlearning
