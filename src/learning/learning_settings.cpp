#include "cartpole_qlearning/learning/learning_settings.h"

#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

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

namespace
{
// Each field as the server names it, with its value as text.
std::vector<std::pair<std::string, std::string>> fieldsOf(const LearningSettings& s)
{
  const auto number = [](double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  };
  const auto override = [&](const std::optional<double>& value) { return value ? number(*value) : "none"; };
  std::vector<std::pair<std::string, std::string>> fields{{"epsilon_override", override(s.epsilon_override)},
                                                          {"alpha_override", override(s.alpha_override)},
                                                          {"gamma", number(s.gamma)}};
  // A named array, not a braced list of temporaries in the loop's head (GCC 14's -Wdangling-reference).
  const std::pair<const char*, const ScheduleParams*> schedules[] = {{"epsilon_", &s.epsilon}, {"alpha_", &s.alpha}};
  for (const auto& [name, p] : schedules)
  {
    fields.emplace_back(name + std::string("schedule"), toString(p->type));
    fields.emplace_back(name + std::string("start"), number(p->start));
    fields.emplace_back(name + std::string("min"), number(p->min));
    fields.emplace_back(name + std::string("decay_episodes"), number(p->decay_episodes));
    fields.emplace_back(name + std::string("decay_rate"), number(p->decay_rate));
    fields.emplace_back(name + std::string("log_divisor"), number(p->log_divisor));
  }
  return fields;
}

std::string scheduleText(const ScheduleParams& p)
{
  std::ostringstream out;
  out << toString(p.type) << " " << p.start;
  if (p.type == ScheduleType::Linear)
    out << " -> " << p.min << " over " << p.decay_episodes << " episodes";
  if (p.type == ScheduleType::Exponential)
    out << " -> " << p.min << " by x" << p.decay_rate << " per episode";
  if (p.type == ScheduleType::Log)
    out << " -> " << p.min << " (log_divisor " << p.log_divisor << ")";
  return out.str();
}

}  // namespace

// "gamma 0.99 -> 0.95, epsilon_override none -> 0" ("" when nothing differs).
std::string learningChangesText(const LearningSettings& before, const LearningSettings& after)
{
  const auto old_fields = fieldsOf(before);
  const auto new_fields = fieldsOf(after);
  std::string text;
  for (std::size_t i = 0; i < old_fields.size(); ++i)
  {
    if (old_fields[i].second != new_fields[i].second)
      text +=
          (text.empty() ? "" : ", ") + old_fields[i].first + " " + old_fields[i].second + " -> " + new_fields[i].second;
  }
  return text;
}

// "epsilon 0 (override; schedule log 1 -> 0.01 (log_divisor 25)), alpha log 1 -> 0.05 (...), gamma 0.99"
std::string learningSettingsText(const LearningSettings& s)
{
  const auto rate = [](const ScheduleParams& schedule, const std::optional<double>& value) {
    if (!value)
      return scheduleText(schedule);
    std::ostringstream out;
    out << *value << " (override; schedule " << scheduleText(schedule) << ")";
    return out.str();
  };
  std::ostringstream out;
  out << "epsilon " << rate(s.epsilon, s.epsilon_override) << ", alpha " << rate(s.alpha, s.alpha_override)
      << ", gamma " << s.gamma;
  return out.str();
}

LogLines liveTuningLog(const LearningSettings& in_use, const LearningSettings& wanted, const std::string& error,
                       bool restarted, bool learning)
{
  if (!error.empty())
  {
    if (restarted)
      return {{LogLine::Level::Warn,
               "restarted; the live tuning left by the controller before the restart is refused (" + error +
                   "): this run goes on with its configuration's: " + learningSettingsText(in_use)}};
    return {{LogLine::Level::Warn, "live tuning refused (asked: " + learningChangesText(in_use, wanted) +
                                       "): " + error + "; nothing changed, in use: " + learningSettingsText(in_use)}};
  }
  const std::string changes = learningChangesText(in_use, wanted);
  if (changes.empty())
    return {};
  const std::string applies = learning ? "gamma from the next update, epsilon and alpha from the next episode"
                                       : "evaluating, so none of it applies: actions stay greedy (epsilon 0), nothing "
                                         "is learnt (alpha 0, gamma unused)";
  if (restarted)
    return {{LogLine::Level::Warn, "restarted; the live tuning of this run before the restart applies again: " +
                                       changes + " (" + applies + ")"}};
  return {{LogLine::Level::Info, "live tuning: " + changes + " (" + applies + ")"}};
}

LogLines liveTuningReplacedLog(const LearningSettings& left, const LearningSettings& configured)
{
  const std::string replaced = learningChangesText(left, configured);
  if (replaced.empty())
    return {};
  return {{LogLine::Level::Info,
           "a new run: live-tuning values left on the parameter server replaced by its configuration's: " + replaced}};
}

}  // namespace cartpole_qlearning
