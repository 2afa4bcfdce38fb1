#include "cartpole_qlearning/learning/eligibility_traces.h"

namespace cartpole_qlearning
{
void EligibilityTraces::clear()
{
  for (const std::uint32_t index : indices_)
    slot_[index] = -1;
  indices_.clear();
  traces_.clear();
}

void EligibilityTraces::visit(const ActiveRows& state, std::size_t action, std::size_t actions, std::size_t values)
{
  if (slot_.size() != values)
  {
    indices_.clear();
    traces_.clear();
    slot_.assign(values, -1);
  }
  for (unsigned i = 0; i < state.count; ++i)
  {
    const auto index = static_cast<std::uint32_t>(state.rows[i] * actions + action);
    std::int32_t& slot = slot_[index];
    if (slot >= 0)
    {
      traces_[static_cast<std::size_t>(slot)] = 1.0;
      continue;
    }
    slot = static_cast<std::int32_t>(indices_.size());
    indices_.push_back(index);
    traces_.push_back(1.0);
  }
}

void EligibilityTraces::decay(double factor)
{
  std::size_t kept = 0;
  for (std::size_t i = 0; i < indices_.size(); ++i)
  {
    const double trace = traces_[i] * factor;
    if (trace < kFloor)
    {
      slot_[indices_[i]] = -1;
      continue;
    }
    indices_[kept] = indices_[i];
    traces_[kept] = trace;
    slot_[indices_[kept]] = static_cast<std::int32_t>(kept);
    ++kept;
  }
  indices_.resize(kept);
  traces_.resize(kept);
}

double EligibilityTraces::trace(std::size_t index) const
{
  if (index >= slot_.size() || slot_[index] < 0)
    return 0.0;
  return traces_[static_cast<std::size_t>(slot_[index])];
}

}  // namespace cartpole_qlearning
