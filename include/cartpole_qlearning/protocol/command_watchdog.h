// The command watchdog between a controller and a robot (the twist_mux / diff_drive_controller
// cmd_vel_timeout pattern): a robot that holds its last command (ros_control's
// JointEffortController holds it for ever) is never left pushed by a controller that stopped
// commanding, hung, died (even by kill -9, which leaves it no chance to send its own zero) or
// sends garbage.
//
// The node feeds it what happens: each command from the controller (its effort), each change in
// the number of the controller's publishers, its timer and its own shutdown; the watchdog answers
// what to do with it: forward the command as it came, send the robot 0, or nothing. Times are
// injected. The count (ros::Subscriber::getNumPublishers) drops when the controller unregisters
// (it ended, was restarted, `rosnode kill`); after kill -9 or a crash roscpp keeps the link and
// retries it, since the master still lists the dead node, so it is the timeout that stops the
// robot then (about 0.1 s: command_watchdog.test). It acts only while the robot may be pushed (the
// last command forwarded was not 0): a controller that sent 0 and went quiet leaves nothing to
// stop.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/common/setting_names.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <cstddef>
#include <optional>

namespace cartpole_qlearning
{
class CommandWatchdog
{
public:
  enum class Action
  {
    Nothing,  // drop the command, or nothing to do
    Forward,  // publish the command as it came
    SendZero  // publish 0 to the robot now
  };

  // timeout: 0 when no command came for this long while the robot may be pushed; zero: no timeout
  // (a lockstep sim, which holds no command and waits for each one): only a lost controller and
  // the watchdog's own end send 0. names: how the front end names the timeout, for what is said.
  explicit CommandWatchdog(WallClock::duration timeout, SettingNames names = {});

  // A command from the controller, its effort as the robot takes it. A command that comes while
  // the controller's publishers are known to be gone (one still in flight when it died) is
  // dropped: forwarded after the zero, it would push the robot with nobody left to stop it.
  Action onCommand(double effort, WallClock::time_point now, LogLines& log);
  // The number of publishers on the watchdog's input now (the node asks before each command and
  // at each tick; an unchanged count is nothing).
  Action onPublishers(std::size_t count, LogLines& log);
  // The timer.
  Action onTick(WallClock::time_point now, LogLines& log);
  // The watchdog itself is ending (Ctrl-C, roslaunch ending after its required controller died).
  Action onShutdown(LogLines& log);

  // The robot may be pushed: the last command forwarded was not 0, and no 0 was sent since.
  bool pushing() const
  {
    return pushing_;
  }

private:
  Action stop(const std::string& why, LogLines& log);

  WallClock::duration timeout_;
  SettingNames names_;
  bool pushing_ = false;
  std::optional<WallClock::time_point> last_command_;
  std::size_t publishers_ = 0;
  bool publisher_lost_ = false;  // the count fell to 0: commands dropped until a publisher is back
  bool stopped_ = false;         // a 0 was sent for a reason, said once; the next forward says they are back
  bool said_dropped_ = false;    // a dropped command was said (once per loss)
};

}  // namespace cartpole_qlearning
