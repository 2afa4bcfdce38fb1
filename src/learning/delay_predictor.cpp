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
  // Each episode's robot may be another draw (masses, motor): fitted afresh.
  fitted_for_ = told_;
  restartFit(start);
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
  const unsigned steps_now = steps();
  if (!last_ || steps_now != fitted_for_)
  {
    // A fit and an estimate made under another delay took other commands as acting: start both
    // afresh from this state.
    fitted_for_ = steps_now;
    restartFit(state);
    return;
  }
  if (steps_now == 0)
  {
    last_ = state;
    return;
  }
  const double acted = actedCommand();
  const std::array<double, 2> forces{0.0, acted};
  std::array<CartPoleState, 2> model{};
  model_.stepEach(*last_, forces.data(), forces.size(), model.data());
  for (std::size_t v = 0; v < 2; ++v)
  {
    const std::size_t d = 2 * v + 1;  // x_dot, theta_dot
    const double z0 = model[0][d] - (*last_)[d];
    const double zf = model[1][d] - model[0][d];
    const double y = state[d] - (*last_)[d];
    std::array<double, 5>& sum = sums_[v];
    const double terms[5] = {z0 * z0, z0 * zf, zf * zf, z0 * y, zf * y};
    for (std::size_t k = 0; k < 5; ++k)
      sum[k] = kFitForgetting * sum[k] + terms[k];
    // Least squares of y on (z0, zf), each gain pulled towards 1 by kFitPullToModel.
    const double a = sum[0] + kFitPullToModel;
    const double b = sum[1];
    const double c = sum[2] + kFitPullToModel;
    const double det = a * c - b * b;
    if (det > 0.0)
    {
      const double r0 = sum[3] + kFitPullToModel;
      const double r1 = sum[4] + kFitPullToModel;
      gains_[v].gravity = std::clamp((r0 * c - b * r1) / det, kFitLowest, kFitHighest);
      gains_[v].force = std::clamp((a * r1 - b * r0) / det, kFitLowest, kFitHighest);
    }
  }
  // The estimate: advanced by the fitted step, then most of the way to the reading.
  const CartPoleState advanced = fittedStep(estimate_, acted);
  estimate_ = advanced + kObserverGain * (state - advanced);
  last_ = state;
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
  const unsigned steps_now = steps();
  if (steps_now == 0)
    return observed;
  // The estimate is of the state last observed (and made under this delay): another state given
  // here is taken as it is.
  CartPoleState state = last_ && fitted_for_ == steps_now && *last_ == observed ? estimate_ : observed;
  // In flight: the last `steps` commands, the oldest acting first.
  for (std::size_t back = steps_now; back-- > 0;)
    state = fittedStep(state, model_.clampForce(sent_[(newest_ + sent_.size() - back) % sent_.size()]));
  return state;
}

double DelayPredictor::actedCommand() const
{
  return model_.clampForce(sent_[(newest_ + sent_.size() - steps()) % sent_.size()]);
}

CartPoleState DelayPredictor::fittedStep(const CartPoleState& state, double force) const
{
  const std::array<double, 2> forces{0.0, force};
  std::array<CartPoleState, 2> model{};
  model_.stepEach(state, forces.data(), forces.size(), model.data());
  CartPoleState next = model[1];
  // The fitted velocity's difference from the model's moves the position as the integrator would.
  const double carried = model_.velocityChangeInPosition();
  for (std::size_t v = 0; v < 2; ++v)
  {
    const std::size_t d = 2 * v + 1;
    const double fitted =
        state[d] + gains_[v].gravity * (model[0][d] - state[d]) + gains_[v].force * (model[1][d] - model[0][d]);
    next[d - 1] += carried * model_.params().tau * (fitted - next[d]);
    next[d] = fitted;
  }
  return next;
}

void DelayPredictor::restartFit(const CartPoleState& state)
{
  for (std::array<double, 5>& sum : sums_)
    sum.fill(0.0);
  gains_ = {};
  last_ = state;
  estimate_ = state;
}

}  // namespace cartpole_qlearning
