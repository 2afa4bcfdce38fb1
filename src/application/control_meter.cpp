#include "cartpole_qlearning/application/control_meter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
std::string seconds(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", value);
  return text;
}

std::string newtons(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%g N", value);
  return text;
}
}  // namespace

ControlMeter::ControlMeter(std::string robot, double tau, double max_gap, double max_effort, double report_every)
  : robot_(std::move(robot)), tau_(tau), max_gap_(max_gap), max_effort_(max_effort), report_every_(report_every)
{
}

LogLines ControlMeter::onReaction(const Reaction& reaction, bool fell)
{
  LogLines log;
  if (reaction.kind != Reaction::Kind::New)
    return log;  // a repeat, a stale or stray state: no new decision, no time
  if (reaction.sim_restarted)
  {
    // Time went back (a sim restarted): the stretch is abandoned, not a fall, and the clock
    // starts again from this stamp.
    in_episode_ = false;
    stats_.current_seconds = 0.0;
    last_stamp_ = 0;
  }
  if (reaction.clock_set_back)
    last_stamp_ = 0;  // the stretch goes on; the robot's clock starts again from this stamp
  if (reaction.episode_began)
    in_episode_ = true;
  if (reaction.episode_ended)
  {
    in_episode_ = false;
    if (fell)
    {
      ++stats_.falls;
      log.push_back({LogLine::Level::Warn, "control" + (robot_.empty() ? std::string() : " (" + robot_ + ")") +
                                               ": the pole fell after " + seconds(stats_.current_seconds) +
                                               " balanced; " + reportText()});
    }
    stats_.current_seconds = 0.0;
  }
  if (!reaction.answer)
    return log;
  // The time since the last decision, by the stamps; a decision without stamps counts tau.
  double dt = tau_;
  if (reaction.stamp > 0 && last_stamp_ > 0 && reaction.stamp > last_stamp_)
    dt = std::min(static_cast<double>(reaction.stamp - last_stamp_) * 1e-9, max_gap_);
  else if (reaction.stamp > 0 && last_stamp_ == 0)
    dt = 0.0;  // the first stamp: the clock starts here
  last_stamp_ = reaction.stamp;
  ++stats_.decisions;
  stats_.seconds += dt;
  if (in_episode_)
  {
    stats_.balanced_seconds += dt;
    stats_.current_seconds += dt;
    stats_.longest_seconds = std::max(stats_.longest_seconds, stats_.current_seconds);
  }
  if (std::abs(reaction.effort) > max_effort_)
    ++stats_.clamped;
  since_report_ += dt;
  if (since_report_ >= report_every_ - 1e-9)
  {
    since_report_ = 0.0;
    if (log.empty())
      log.push_back({LogLine::Level::Info,
                     "control" + (robot_.empty() ? std::string() : " (" + robot_ + ")") + ": " + reportText()});
  }
  return log;
}

std::string ControlMeter::reportText() const
{
  const ControlStatsValues& s = stats_;
  return "balanced " + seconds(s.balanced_seconds) + " of " + seconds(s.seconds) + ", the longest stretch " +
         seconds(s.longest_seconds) + ", " + std::to_string(s.falls) + (s.falls == 1 ? " fall, " : " falls, ") +
         (std::isfinite(max_effort_) ? std::to_string(s.clamped) + " of " + std::to_string(s.decisions) +
                                           " commands beyond the motor's " + newtons(max_effort_)
                                     : std::to_string(s.decisions) + " commands (the motor's limit not given)");
}

LogLine ControlMeter::summary() const
{
  return {LogLine::Level::Info,
          "control" + (robot_.empty() ? std::string() : " (" + robot_ + ")") + " ended: " + reportText()};
}

}  // namespace cartpole_qlearning
