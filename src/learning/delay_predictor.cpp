#include "cartpole_qlearning/learning/delay_predictor.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
DelayPredictor::DelayPredictor(const CartPoleParams& model, unsigned steps) : model_(model)
{
  if (steps == kDelayFoundFromStates)
    estimator_.emplace(model);
  else if (steps > kMaxPredictedDelaySteps)
    throw std::invalid_argument("a prediction of " + std::to_string(steps) + " steps is not allowed (must be in [0, " +
                                std::to_string(kMaxPredictedDelaySteps) + "])");
  else
    told_ = steps;
  sent_.assign(std::max(told_, kLargestFoundDelay) + 1, 0.0);
}

unsigned DelayPredictor::steps() const
{
  return estimator_ ? estimator_->estimate().value_or(0) : told_;
}

void DelayPredictor::begin(const CartPoleState& start)
{
  std::fill(sent_.begin(), sent_.end(), 0.0);
  // Each episode finds the delay afresh from its own states: its decisions never depend on the
  // episodes before it (a suite's episodes run in any order, on any thread, and a verdict cut
  // short goes on as if run whole), at the cost of its first second or so deciding for the state
  // observed.
  if (estimator_)
  {
    estimator_.emplace(model_.params());
    estimator_->begin(start);
  }
}

void DelayPredictor::observed(const CartPoleState& state)
{
  if (estimator_)
    estimator_->observed(state);
}

void DelayPredictor::sent(double effort)
{
  newest_ = (newest_ + 1) % sent_.size();
  sent_[newest_] = effort;
  if (estimator_)
    estimator_->sent(effort);
}

CartPoleState DelayPredictor::predict(const CartPoleState& observed) const
{
  CartPoleState state = observed;
  // In flight: the last `steps` commands, the oldest acting first.
  for (std::size_t back = steps(); back-- > 0;)
    state = model_.step(state, model_.clampForce(sent_[(newest_ + sent_.size() - back) % sent_.size()]));
  return state;
}

}  // namespace cartpole_qlearning
