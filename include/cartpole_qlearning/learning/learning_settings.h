// The learning settings a running learner may change (live tuning): the discount and the
// epsilon and alpha schedules, each with an optional override that holds its rate constant.
// The discretisation and the actions are not among them: they fix the table's shape.
#pragma once

#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/learning/schedule.h"

#include <optional>
#include <string>

namespace cartpole_qlearning
{
struct LearningSettings
{
  double gamma = 0.99;
  ScheduleParams epsilon = AgentParams::defaultEpsilon();
  ScheduleParams alpha = AgentParams::defaultAlpha();
  std::optional<double> epsilon_override;  // set: epsilon is this every episode, whatever the schedule says
  std::optional<double> alpha_override;    // set: alpha is this every episode

  // The configuration's settings, no override.
  static LearningSettings of(const AgentParams& agent);

  // Empty when valid, else a message naming the first bad field ("gamma", "epsilon/min",
  // "alpha_override", ...), its value and what is allowed. gamma and both schedules get the
  // config file's checks (AgentParams::validate), a schedule even while it is overridden, so that
  // going back to it always finds it valid.
  std::string validate() const;

  // What applies: the override as a constant schedule, else the schedule.
  ScheduleParams effectiveEpsilon() const;
  ScheduleParams effectiveAlpha() const;
};

// What differs, field by field in the names of the live-tuning server and of the parameters:
// "gamma 0.99 -> 0.95, epsilon_override none -> 0" ("" when nothing differs).
std::string learningChangesText(const LearningSettings& before, const LearningSettings& after);
// The settings in use, for the console: "epsilon 0 (override; schedule log 1 -> 0.01
// (log_divisor 25)), alpha log 1 -> 0.05 (log_divisor 15), gamma 0.99".
std::string learningSettingsText(const LearningSettings& settings);

// What live tuning says about a client's change. in_use: the settings before it; wanted: what
// was asked; error: why it was refused, with the field named as the server names it ("" when it
// applied); restarted: the first change a respawned controller gets (its predecessor's tuning of
// this run, served again); learning: training (else evaluating, where none of it applies).
// Nothing is said of a change that changes nothing.
LogLines liveTuningLog(const LearningSettings& in_use, const LearningSettings& wanted, const std::string& error,
                       bool restarted, bool learning);
// A new run found values an earlier controller left on the parameter server and replaces them
// by its configuration's (nothing said when they were the same).
LogLines liveTuningReplacedLog(const LearningSettings& left, const LearningSettings& configured);

}  // namespace cartpole_qlearning
