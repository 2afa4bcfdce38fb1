#include "cartpole_qlearning/learning/schedule.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
ScheduleType scheduleTypeFromString(const std::string& name)
{
  if (name == "constant")
    return ScheduleType::Constant;
  if (name == "linear")
    return ScheduleType::Linear;
  if (name == "exponential")
    return ScheduleType::Exponential;
  if (name == "log")
    return ScheduleType::Log;
  throw std::invalid_argument("unknown schedule '" + name + "' (allowed: constant, linear, exponential, log)");
}

std::string toString(ScheduleType type)
{
  switch (type)
  {
    case ScheduleType::Constant:
      return "constant";
    case ScheduleType::Linear:
      return "linear";
    case ScheduleType::Exponential:
      return "exponential";
    case ScheduleType::Log:
      return "log";
  }
  return "unknown";
}

std::string ScheduleParams::validate() const
{
  std::ostringstream out;
  const auto rate = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= 1.0; };
  if (!rate(start))
    out << "start = " << start << " is not allowed (must be in [0, 1])";
  else if (!rate(min) || min > start)
    out << "min = " << min << " is not allowed (must be in [0, start = " << start << "])";
  else if (type == ScheduleType::Linear && !(std::isfinite(decay_episodes) && decay_episodes > 0.0))
    out << "decay_episodes = " << decay_episodes << " is not allowed (must be > 0)";
  else if (type == ScheduleType::Exponential && !(std::isfinite(decay_rate) && decay_rate > 0.0 && decay_rate <= 1.0))
    out << "decay_rate = " << decay_rate << " is not allowed (must be in (0, 1])";
  else if (type == ScheduleType::Log && !(std::isfinite(log_divisor) && log_divisor > 0.0))
    out << "log_divisor = " << log_divisor << " is not allowed (must be > 0)";
  return out.str();
}

Schedule::Schedule(const ScheduleParams& params) : params_(params)
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
}

double Schedule::value(unsigned long episode) const
{
  const double e = static_cast<double>(episode);
  switch (params_.type)
  {
    case ScheduleType::Constant:
      return params_.start;
    case ScheduleType::Linear:
      return std::max(params_.min, params_.start - (params_.start - params_.min) * e / params_.decay_episodes);
    case ScheduleType::Exponential:
      return std::max(params_.min, params_.start * std::pow(params_.decay_rate, e));
    case ScheduleType::Log:
      return std::max(params_.min, std::min(params_.start, 1.0 - std::log10((e + 1.0) / params_.log_divisor)));
  }
  return params_.start;
}

}  // namespace cartpole_qlearning
