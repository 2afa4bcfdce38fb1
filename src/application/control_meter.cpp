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

ControlMeter::ControlMeter(std::string robot, double tau, double max_gap, double max_effort, double report_every,
                           TaskKind task, double rail_limit)
  : robot_(std::move(robot)),
    tau_(tau),
    max_gap_(max_gap),
    max_effort_(max_effort),
    report_every_(report_every),
    never_ends_(isSuiteTask(task)),
    rail_limit_(rail_limit)
{
}

std::string ControlMeter::name() const
{
  return "control" + (robot_.empty() ? std::string() : " (" + robot_ + ")");
}

void ControlMeter::measure(const CartPoleState& state, double dt, LogLines& log)
{
  const double now = stats_.seconds;
  const double up = std::cos(state[2]);
  if (up >= kUprightCos)
    stats_.upright_seconds += dt;
  if (rail_limit_ > 0.0)
  {
    const double from_end = rail_limit_ - std::abs(state[0]);
    if (!at_rail_end_ && from_end <= kRailHitMargin)
    {
      at_rail_end_ = true;
      ++stats_.rail_hits;
    }
    else if (at_rail_end_ && from_end > kRailLeaveMargin)
      at_rail_end_ = false;
  }
  if (!never_ends_)
    return;
  if (stats_.decisions == 1 && up >= kUprightCos)
    up_ = true;  // control began with the pole up: no swing-up to count
  if (up_)
  {
    if (up >= 0.0)
      return;
    up_ = false;
    ++stats_.falls;
    down_since_ = now;
    upright_since_.reset();
    log.push_back({LogLine::Level::Warn, name() + ": the pole fell after " + seconds(stats_.current_seconds) +
                                             " balanced (below the horizontal; swinging it up again); " +
                                             reportText()});
    stats_.current_seconds = 0.0;
    return;
  }
  if (up < kUprightCos)
  {
    upright_since_.reset();
    return;
  }
  if (!upright_since_)
    upright_since_ = now;
  if (now - *upright_since_ < kSwingUpHoldSeconds - 1e-9)
    return;
  // Held upright: a swing-up, which took from going down to coming up; the stretch up began then.
  up_ = true;
  ++stats_.swing_ups;
  stats_.last_swing_up_seconds = *upright_since_ - down_since_;
  stats_.longest_swing_up_seconds = std::max(stats_.longest_swing_up_seconds, stats_.last_swing_up_seconds);
  stats_.current_seconds = now - *upright_since_;
  stats_.balanced_seconds += stats_.current_seconds;
  stats_.longest_seconds = std::max(stats_.longest_seconds, stats_.current_seconds);
  log.push_back({LogLine::Level::Info, name() + ": swung the pole up in " + seconds(stats_.last_swing_up_seconds) +
                                           " (swing-up " + std::to_string(stats_.swing_ups) + "); " + reportText()});
}

LogLines ControlMeter::onReaction(const Reaction& reaction, bool fell, const std::optional<CartPoleState>& state)
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
      log.push_back({LogLine::Level::Warn, name() + ": the pole fell after " + seconds(stats_.current_seconds) +
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
  if (never_ends_ ? up_ : in_episode_)
  {
    stats_.balanced_seconds += dt;
    stats_.current_seconds += dt;
    stats_.longest_seconds = std::max(stats_.longest_seconds, stats_.current_seconds);
  }
  if (std::abs(reaction.effort) > max_effort_)
    ++stats_.clamped;
  if (state)
    measure(*state, dt, log);
  since_report_ += dt;
  if (since_report_ >= report_every_ - 1e-9)
  {
    since_report_ = 0.0;
    if (log.empty())
      log.push_back({LogLine::Level::Info, name() + ": " + reportText()});
  }
  return log;
}

std::string ControlMeter::reportText() const
{
  const ControlStatsValues& s = stats_;
  const auto count = [](std::uint64_t n, const char* one, const char* many) {
    return std::to_string(n) + (n == 1 ? one : many);
  };
  std::string swing;
  if (never_ends_)
    swing = "upright " + seconds(s.upright_seconds) + " of " + seconds(s.seconds) + " (cos(theta) >= 0.95), " +
            count(s.swing_ups, " swing-up", " swing-ups") +
            (s.swing_ups > 0 ? " (the last took " + seconds(s.last_swing_up_seconds) + ", the longest " +
                                   seconds(s.longest_swing_up_seconds) + ")"
                             : std::string()) +
            ", ";
  const std::string rail = rail_limit_ > 0.0 ? count(s.rail_hits, " hit", " hits") + " of the rail's ends, " : "";
  return swing + "balanced " + seconds(s.balanced_seconds) + " of " + seconds(s.seconds) + ", the longest stretch " +
         seconds(s.longest_seconds) + ", " + std::to_string(s.falls) + (s.falls == 1 ? " fall, " : " falls, ") + rail +
         (std::isfinite(max_effort_) ? std::to_string(s.clamped) + " of " + std::to_string(s.decisions) +
                                           " commands beyond the motor's " + newtons(max_effort_)
                                     : std::to_string(s.decisions) + " commands (the motor's limit not given)");
}

LogLine ControlMeter::summary() const
{
  return {LogLine::Level::Info, name() + " ended: " + reportText()};
}

}  // namespace cartpole_qlearning
