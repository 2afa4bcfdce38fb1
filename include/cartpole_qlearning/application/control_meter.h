// What a robot owner wants to know of a table that drives a robot (~mode control): how long it
// has kept the pole up, its longest stretch, how often the pole fell, how many commands were
// beyond the motor. Time is the robot's own clock, whatever the wall clock does (a lockstep sim
// runs faster than real time): the stamps of the states decided on, each decision counting the
// time since the one before (at most max_gap: a robot silent for longer was not being controlled),
// or tau for a robot that sends no stamps.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <cstdint>
#include <string>

namespace cartpole_qlearning
{
struct ControlStatsValues
{
  double seconds = 0.0;           // decisions on new states x tau, balancing or waiting for a start
  double balanced_seconds = 0.0;  // of which inside an episode (the pole up)
  double longest_seconds = 0.0;   // the longest stretch without a fall
  double current_seconds = 0.0;   // the stretch going on (0 while waiting for a start)
  std::uint64_t falls = 0;
  std::uint64_t decisions = 0;
  std::uint64_t clamped = 0;  // decisions whose effort was beyond the motor's limit (clamped to it)
};

class ControlMeter
{
public:
  // robot: as the log names it ("" the learner's own); tau: the step the table learnt [s] (the
  // time of a decision without stamps); max_gap: the most time one decision counts [s];
  // max_effort: the motor's limit as the robot's owner gave it [N] (commands beyond it were
  // clamped to it; infinity: not given, and nothing is counted); report_every: a report line
  // every this much robot time [s].
  ControlMeter(std::string robot, double tau, double max_gap, double max_effort, double report_every);

  // One of the robot's states as the protocol reacted to it (reaction.stamp its stamp, 0: none);
  // fell: the episode it ended ended on the task's thresholds (TrainingSession::lastEpisode()
  // .terminated). Returns what to say: the fall, or the periodic report when due; empty
  // otherwise (publish the stats when not empty).
  LogLines onReaction(const Reaction& reaction, bool fell);
  // The line said at the end (the controller stopping).
  LogLine summary() const;

  const ControlStatsValues& stats() const
  {
    return stats_;
  }

private:
  std::string reportText() const;

  std::string robot_;
  double tau_;
  double max_gap_;
  double max_effort_;
  double report_every_;
  bool in_episode_ = false;
  Stamp last_stamp_ = 0;  // of the last decision (0: none yet, or no stamps)
  double since_report_ = 0.0;
  ControlStatsValues stats_;
};

}  // namespace cartpole_qlearning
