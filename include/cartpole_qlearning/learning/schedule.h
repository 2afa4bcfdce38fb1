// Per-episode schedules for the exploration rate epsilon and the learning rate alpha.
#pragma once

#include <string>

namespace cartpole_qlearning
{
enum class ScheduleType
{
  Constant,     // start, every episode
  Linear,       // from start down to min over decay_episodes episodes
  Exponential,  // start * decay_rate^episode, floored at min
  Log           // the tutorial's: min(start, 1 - log10((episode + 1) / log_divisor)), floored at min
};

// Parses "constant", "linear", "exponential" or "log"; throws std::invalid_argument otherwise.
ScheduleType scheduleTypeFromString(const std::string& name);
std::string toString(ScheduleType type);

struct ScheduleParams
{
  ScheduleType type = ScheduleType::Log;
  double start = 1.0;
  double min = 0.01;
  double decay_episodes = 500.0;  // linear only
  double decay_rate = 0.995;      // exponential only, in (0, 1]
  double log_divisor = 25.0;      // log only, > 0

  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  // Values must lie in [0, 1] (both epsilon and alpha are rates).
  std::string validate() const;
};

class Schedule
{
public:
  explicit Schedule(const ScheduleParams& params = ScheduleParams());

  const ScheduleParams& params() const
  {
    return params_;
  }

  // The value for an episode, counted from 0.
  double value(unsigned long episode) const;

private:
  ScheduleParams params_;
};

}  // namespace cartpole_qlearning
