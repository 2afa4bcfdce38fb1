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

ControlMeter::ControlMeter(std::string robot, double tau, double force_mag, double report_every)
  : robot_(std::move(robot)),
    tau_(tau),
    force_mag_(force_mag),
    report_every_(std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(report_every / tau))))
{
}

LogLines ControlMeter::onReaction(const Reaction& reaction, bool fell)
{
  LogLines log;
  if (reaction.kind != Reaction::Kind::New)
    return log;  // a repeat, a stale or stray state: no new decision, no time
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
  ++stats_.decisions;
  stats_.seconds += tau_;
  if (in_episode_)
  {
    stats_.balanced_seconds += tau_;
    stats_.current_seconds += tau_;
    stats_.longest_seconds = std::max(stats_.longest_seconds, stats_.current_seconds);
  }
  if (std::abs(reaction.effort) > force_mag_)
    ++stats_.clamped;
  if (++since_report_ >= report_every_)
  {
    since_report_ = 0;
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
         std::to_string(s.clamped) + " of " + std::to_string(s.decisions) + " commands beyond the motor's " +
         newtons(force_mag_);
}

LogLine ControlMeter::summary() const
{
  return {LogLine::Level::Info,
          "control" + (robot_.empty() ? std::string() : " (" + robot_ + ")") + " ended: " + reportText()};
}

}  // namespace cartpole_qlearning
