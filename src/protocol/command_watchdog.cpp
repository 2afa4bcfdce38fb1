#include "cartpole_qlearning/protocol/command_watchdog.h"

#include <chrono>
#include <cmath>
#include <string>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
double seconds(WallClock::duration d)
{
  return std::chrono::duration<double>(d).count();
}
}  // namespace

CommandWatchdog::CommandWatchdog(WallClock::duration timeout, SettingNames names)
  : timeout_(timeout), names_(std::move(names))
{
}

CommandWatchdog::Action CommandWatchdog::stop(const std::string& why, LogLines& log)
{
  stopped_ = true;
  if (!pushing_)
    return Action::Nothing;  // the robot already has 0 (or was never pushed)
  pushing_ = false;
  log.push_back({LogLine::Level::Warn, why + ": 0 sent to the robot", true});
  return Action::SendZero;
}

CommandWatchdog::Action CommandWatchdog::onCommand(double effort, WallClock::time_point now, LogLines& log)
{
  if (publisher_lost_)
  {
    if (!said_dropped_)
      log.push_back({LogLine::Level::Warn,
                     "dropped a command that came after the controller's publisher was gone (sent before it died)",
                     true});
    said_dropped_ = true;
    return Action::Nothing;
  }
  if (!std::isfinite(effort))
  {
    // The controller is alive but its command is no number: the robot must not keep the one before.
    const bool was_pushing = pushing_;
    const Action action = stop("the controller commanded " + std::to_string(effort), log);
    if (!was_pushing)
      log.push_back({LogLine::Level::Warn, "dropped a command of " + std::to_string(effort), true});
    return action;
  }
  if (stopped_)
    log.push_back({LogLine::Level::Info, "the controller's commands are back: forwarding them", true});
  stopped_ = false;
  last_command_ = now;
  pushing_ = effort != 0.0;
  return Action::Forward;
}

CommandWatchdog::Action CommandWatchdog::onPublishers(std::size_t count, LogLines& log)
{
  const std::size_t before = publishers_;
  publishers_ = count;
  if (count > 0)
  {
    publisher_lost_ = false;
    said_dropped_ = false;
    return Action::Nothing;
  }
  if (before == 0)
    return Action::Nothing;
  publisher_lost_ = true;
  return stop("the controller's publisher is gone (the controller ended or died)", log);
}

CommandWatchdog::Action CommandWatchdog::onTick(WallClock::time_point now, LogLines& log)
{
  if (timeout_ <= WallClock::duration::zero() || !pushing_ || !last_command_ || now - *last_command_ < timeout_)
    return Action::Nothing;
  return stop(formatText("no command for %.3f s (%s %.3f s)", seconds(now - *last_command_),
                         names_(Setting::CommandTimeout).c_str(), seconds(timeout_)),
              log);
}

CommandWatchdog::Action CommandWatchdog::onShutdown(LogLines& log)
{
  return stop("the watchdog is ending", log);
}

}  // namespace cartpole_qlearning
