// What a robot owner wants to know of a table that drives a robot (~mode control): how long it
// has kept the pole up, its longest stretch, how often the pole fell, how many commands were
// beyond the motor; for a swing-up table also how often and how fast it swung the pole up, and
// how often the cart hit the rail's ends. Time is the robot's own clock, whatever the wall clock
// does (a lockstep sim runs faster than real time): the stamps of the states decided on, each
// decision counting the time since the one before (at most max_gap: a robot silent for longer was
// not being controlled), or tau for a robot that sends no stamps.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <cstdint>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
// Upright: cos(theta) >= this (within 18.2 degrees of upright). Down: cos(theta) < 0 (below the
// horizontal). A swing-up: the pole, down (or not up when control started), brought upright and
// kept upright for kSwingUpHoldSeconds; it took the time from going down to coming upright.
constexpr double kUprightCos = 0.95;
constexpr double kSwingUpHoldSeconds = 1.0;
// A rail hit: the cart within this of an end (|x| >= rail_limit - this), counted once per arrival;
// it arrives again only after leaving by kRailLeaveMargin.
constexpr double kRailHitMargin = 0.02;
constexpr double kRailLeaveMargin = 0.1;

struct ControlStatsValues
{
  double seconds = 0.0;           // decisions on new states x tau, balancing or waiting for a start
  double balanced_seconds = 0.0;  // of which with the pole up: inside an episode (CartPole-v1's task), or
                                  // between a swing-up and the next fall (the Suite's, which never end)
  double longest_seconds = 0.0;   // the longest stretch without a fall
  double current_seconds = 0.0;   // the stretch going on (0 while waiting for a start, or down)
  std::uint64_t falls = 0;        // past the task's thresholds, or (never-ending tasks) a pole up gone down
  std::uint64_t decisions = 0;
  std::uint64_t clamped = 0;     // decisions whose effort was beyond the motor's limit (clamped to it)
  double upright_seconds = 0.0;  // with cos(theta) >= kUprightCos
  std::uint64_t swing_ups = 0;   // never-ending tasks only
  double last_swing_up_seconds = 0.0;
  double longest_swing_up_seconds = 0.0;
  std::uint64_t rail_hits = 0;  // arrivals at the rail's ends (none counted without a rail_limit)
};

class ControlMeter
{
public:
  // robot: as the log names it ("" the learner's own); tau: the step the table learnt [s] (the
  // time of a decision without stamps); max_gap: the most time one decision counts [s];
  // max_effort: the motor's limit as the robot's owner gave it [N] (commands beyond it were
  // clamped to it; infinity: not given, and nothing is counted); report_every: a report line
  // every this much robot time [s].
  // task: the table's task kind (one that never ends, the Suite's, is judged by the pole's angle:
  // swing-ups and falls from up to down); rail_limit: the rail's ends at +-this [m] (0: none).
  ControlMeter(std::string robot, double tau, double max_gap, double max_effort, double report_every,
               TaskKind task = TaskKind::CartPoleV1, double rail_limit = 0.0);

  // One of the robot's states as the protocol reacted to it (reaction.stamp its stamp, 0: none);
  // fell: the episode it ended ended on the task's thresholds (TrainingSession::lastEpisode()
  // .terminated); state: the state decided on, as the table sees it (none: the angle and the
  // cart are not measured). Returns what to say: the fall, a swing-up, or the periodic report
  // when due; empty otherwise (publish the stats when not empty).
  LogLines onReaction(const Reaction& reaction, bool fell, const std::optional<CartPoleState>& state = std::nullopt);
  // The line said at the end (the controller stopping).
  LogLine summary() const;

  const ControlStatsValues& stats() const
  {
    return stats_;
  }

private:
  std::string reportText() const;
  std::string name() const;
  // The pole's angle and the cart's place after a decision of dt seconds, at robot time now.
  void measure(const CartPoleState& state, double dt, LogLines& log);

  std::string robot_;
  double tau_;
  double max_gap_;
  double max_effort_;
  double report_every_;
  bool never_ends_;  // the task has no falls of its own: the angle says up and down
  double rail_limit_;
  bool in_episode_ = false;
  // Never-ending tasks: the pole up (swung up and not gone down since); down since, upright since.
  bool up_ = false;
  double down_since_ = 0.0;
  std::optional<double> upright_since_;
  bool at_rail_end_ = false;
  Stamp last_stamp_ = 0;  // of the last decision (0: none yet, or no stamps)
  double since_report_ = 0.0;
  ControlStatsValues stats_;
};

}  // namespace cartpole_qlearning
