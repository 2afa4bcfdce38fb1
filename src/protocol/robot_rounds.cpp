#include "cartpole_qlearning/protocol/robot_rounds.h"

#include <algorithm>
#include <stdexcept>

namespace cartpole_qlearning
{
RobotRounds::RobotRounds(std::size_t robots, bool sync, WallClock::duration drop_out_after, WallClock::time_point start)
  : sync_(sync),
    drop_out_after_(drop_out_after),
    held_(robots, false),
    taking_part_(robots, true),
    last_heard_(robots, start)
{
  if (robots == 0)
    throw std::invalid_argument("RobotRounds: at least one robot");
}

bool RobotRounds::heard(std::size_t robot, WallClock::time_point now)
{
  last_heard_.at(robot) = now;
  if (taking_part_[robot])
    return false;
  taking_part_[robot] = true;
  return true;
}

void RobotRounds::hold(std::size_t robot)
{
  held_.at(robot) = true;
}

bool RobotRounds::roundComplete() const
{
  bool any = false;
  for (std::size_t r = 0; r < held_.size(); ++r)
  {
    if (taking_part_[r] && !held_[r])
      return false;
    any = any || held_[r];
  }
  return any;
}

std::vector<std::size_t> RobotRounds::dropOuts(WallClock::time_point now)
{
  std::vector<std::size_t> dropped;
  if (std::none_of(held_.begin(), held_.end(), [](bool h) { return h; }))
    return dropped;  // nobody waits: a silent robot holds nobody up
  for (std::size_t r = 0; r < held_.size(); ++r)
  {
    if (taking_part_[r] && !held_[r] && now - last_heard_[r] >= drop_out_after_)
    {
      taking_part_[r] = false;
      dropped.push_back(r);
    }
  }
  return dropped;
}

}  // namespace cartpole_qlearning
