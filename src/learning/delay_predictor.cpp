#include "cartpole_qlearning/learning/delay_predictor.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
DelayPredictor::DelayPredictor(const CartPoleParams& model, unsigned steps) : model_(model), in_flight_(steps, 0.0)
{
  if (steps > kMaxPredictedDelaySteps)
    throw std::invalid_argument("a prediction of " + std::to_string(steps) + " steps is not allowed (must be in [0, " +
                                std::to_string(kMaxPredictedDelaySteps) + "])");
}

void DelayPredictor::begin()
{
  std::fill(in_flight_.begin(), in_flight_.end(), 0.0);
  oldest_ = 0;
}

void DelayPredictor::sent(double effort)
{
  if (in_flight_.empty())
    return;
  // The oldest command has now acted; the new one joins the end of the line.
  in_flight_[oldest_] = effort;
  oldest_ = oldest_ + 1 == in_flight_.size() ? 0 : oldest_ + 1;
}

CartPoleState DelayPredictor::predict(const CartPoleState& observed) const
{
  CartPoleState state = observed;
  for (std::size_t i = 0; i < in_flight_.size(); ++i)
  {
    const std::size_t at = (oldest_ + i) % in_flight_.size();
    state = model_.step(state, model_.clampForce(in_flight_[at]));
  }
  return state;
}

}  // namespace cartpole_qlearning
