#include "cartpole_qlearning/learning/delay_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cartpole_qlearning
{
namespace
{
// Recent steps weigh most: a miss halves in weight after about 35 steps (0.7 s at 50 Hz), so a
// push or a burst of noise is forgotten and a delay that changes is found again.
constexpr double kForget = 0.98;
// Decisions whose hypotheses' commands differed by a fifth of the actuator's range or more, before
// the first estimate: fewer could crown a hypothesis by chance.
constexpr unsigned kTellingStepsNeeded = 20;
// The best hypothesis must miss less than this share of the next best's miss.
constexpr double kClearlyBest = 0.5;
}  // namespace

DelayEstimator::DelayEstimator(const CartPoleParams& model) : model_(model), sent_(kLargestFoundDelay + 1, 0.0) {}

void DelayEstimator::begin(const CartPoleState& start)
{
  std::fill(sent_.begin(), sent_.end(), 0.0);
  last_ = start;
}

double DelayEstimator::sentBefore(std::size_t steps) const
{
  if (steps >= sent_.size())
    return 0.0;
  return sent_[(newest_ + sent_.size() - steps) % sent_.size()];
}

void DelayEstimator::sent(double effort)
{
  newest_ = (newest_ + 1) % sent_.size();
  sent_[newest_] = model_.clampForce(effort);
}

void DelayEstimator::observed(const CartPoleState& state)
{
  if (!state.allFinite())
    return;
  if (!last_)
  {
    last_ = state;
    return;
  }
  // The command that acted over the last step, were the robot d steps late, and the state it led to
  // (every hypothesis steps from the same state: one sine and cosine for all).
  std::array<double, kLargestFoundDelay + 1> acted{};
  for (unsigned d = 0; d <= kLargestFoundDelay; ++d)
    acted[d] = sentBefore(d);
  std::array<CartPoleState, kLargestFoundDelay + 1> predicted;
  model_.stepEach(*last_, acted.data(), acted.size(), predicted.data());
  for (unsigned d = 0; d <= kLargestFoundDelay; ++d)
  {
    const CartPoleState miss = state - predicted[d];
    misses_[d] = kForget * misses_[d] + miss[1] * miss[1] + miss[3] * miss[3];
  }
  const auto [lowest, highest] = std::minmax_element(acted.begin(), acted.end());
  last_ = state;
  if (*highest - *lowest >= 0.4 * model_.params().force_mag)
    ++telling_steps_;
  if (telling_steps_ < kTellingStepsNeeded)
    return;
  unsigned best = 0;
  for (unsigned d = 1; d <= kLargestFoundDelay; ++d)
    if (misses_[d] < misses_[best])
      best = d;
  double next = std::numeric_limits<double>::infinity();
  for (unsigned d = 0; d <= kLargestFoundDelay; ++d)
    if (d != best)
      next = std::min(next, misses_[d]);
  if (misses_[best] < kClearlyBest * next)
    estimate_ = best;
}

}  // namespace cartpole_qlearning
