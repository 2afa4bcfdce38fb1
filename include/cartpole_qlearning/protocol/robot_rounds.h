// When a learner serving several robots in lockstep takes their states: in rounds, one new
// state from every robot that takes part, answered in robot order, so that the order of the
// learner's calls (and with it the Q-table) depends on the seed alone. A robot that stays
// silent while the others wait (a host that does not come, a sim that died) drops out after
// a timeout, so the others go on; its next state brings it back, from the next round on.
// Without rounds (sync = false) every state is taken as it comes: real robots at their own
// rates, not reproducible.
#pragma once

#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <cstddef>
#include <vector>

namespace cartpole_qlearning
{
class RobotRounds
{
public:
  // Every robot counts as heard at start.
  RobotRounds(std::size_t robots, bool sync, WallClock::duration drop_out_after, WallClock::time_point start);

  // A state of the robot arrived (any state). Returns true when the robot had dropped out and
  // now takes part again.
  bool heard(std::size_t robot, WallClock::time_point now);
  // Whether a new state of the robot waits for its round (true) or is taken at once (false).
  bool holds() const
  {
    return sync_;
  }
  // The robot's new state waits for its round (replacing one already waiting).
  void hold(std::size_t robot);
  // True when every robot that takes part has a state waiting (and at least one has).
  bool roundComplete() const;
  // Whether the robot has a state waiting; take() it when it is served.
  bool held(std::size_t robot) const
  {
    return held_.at(robot);
  }
  void take(std::size_t robot)
  {
    held_.at(robot) = false;
  }
  // Robots silent for drop_out_after while another robot's state waits: they drop out now
  // (each returned once, until it is heard again).
  std::vector<std::size_t> dropOuts(WallClock::time_point now);
  // How long the robot has been silent: since it was last heard (or since start).
  WallClock::duration silentFor(std::size_t robot, WallClock::time_point now) const
  {
    return now - last_heard_.at(robot);
  }

private:
  bool sync_;
  WallClock::duration drop_out_after_;
  std::vector<bool> held_;
  std::vector<bool> taking_part_;
  std::vector<WallClock::time_point> last_heard_;
};

}  // namespace cartpole_qlearning
