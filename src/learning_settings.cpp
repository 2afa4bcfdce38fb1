#include "cartpole_qlearning/learning_settings.h"

#include <cmath>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
std::string checkOverride(const char* name, const std::optional<double>& value)
{
  if (!value || (std::isfinite(*value) && *value >= 0.0 && *value <= 1.0))
    return "";
  std::ostringstream out;
  out << name << " = " << *value << " is not allowed (must be in [0, 1], or none to follow the schedule)";
  return out.str();
}

ScheduleParams effective(const ScheduleParams& schedule, const std::optional<double>& value)
{
  if (!value)
    return schedule;
  ScheduleParams constant = schedule;
  constant.type = ScheduleType::Constant;
  constant.start = constant.min = *value;
  return constant;
}
}  // namespace

LearningSettings LearningSettings::of(const AgentParams& agent)
{
  LearningSettings settings;
  settings.gamma = agent.gamma;
  settings.epsilon = agent.epsilon;
  settings.alpha = agent.alpha;
  return settings;
}

std::string LearningSettings::validate() const
{
  // The config's own checks: the default discretisation and actions are valid, so only what
  // is set here can fail.
  AgentParams checked;
  checked.gamma = gamma;
  checked.epsilon = epsilon;
  checked.alpha = alpha;
  std::string error = checked.validate();
  if (error.empty())
    error = checkOverride("epsilon_override", epsilon_override);
  if (error.empty())
    error = checkOverride("alpha_override", alpha_override);
  return error;
}

ScheduleParams LearningSettings::effectiveEpsilon() const
{
  return effective(epsilon, epsilon_override);
}

ScheduleParams LearningSettings::effectiveAlpha() const
{
  return effective(alpha, alpha_override);
}

}  // namespace cartpole_qlearning
