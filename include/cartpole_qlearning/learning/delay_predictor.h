// The state a command will meet on a robot that carries commands out `steps` late (ros_control
// hardware answers a control period late: the command decided at state k acts from k + 1). A
// table learnt on a model without that delay decides for the state it sees; by the time its
// command acts, the robot has moved on under the commands sent before. Acting on the state the
// model predicts for that moment (the observed state advanced by the commands still in flight,
// oldest first) is a Smith predictor. The delay is told (a number) or found from how the robot's
// states answer its commands (DelayEstimator): until it is found, and on a robot found prompt, the
// prediction is the observed state.
//
// A robot is not the model (a heavier pole, a weaker motor) and its sensors are noisy, and a
// prediction made with the model's constants from one noisy reading misses by both. So while it
// predicts ahead, the predictor also
//   - fits the robot's step to the model's: each velocity's change over a step is taken as
//     g * (the model's change with no force) + f * (what the model's force adds), g and f fitted
//     by least squares over the last few seconds of the robot's own steps (forgetting older ones,
//     pulled gently towards the model's 1 and 1, kept within [0.5, 2]): a weaker motor shows as
//     f < 1, a longer pole as g < 1 on the pole's velocity;
//   - keeps an estimate of the state, not the last reading alone: each step the estimate advances
//     by the fitted step and moves kObserverGain of the way to the new reading.
// Measured (docs/notes/tuning.md, "A predictor that fits the robot"): robust.yaml's tables of
// seeds 0-9 held 435 of 500 five-minute all_at_once episodes with the model alone, 491 with both.
#pragma once

#include "cartpole_qlearning/learning/delay_estimator.h"
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

namespace cartpole_qlearning
{
// The most steps a prediction may look ahead (a second at 50 Hz).
constexpr unsigned kMaxPredictedDelaySteps = 50;
// As a number of steps: the delay is found from the states (DelayEstimator), not told.
constexpr unsigned kDelayFoundFromStates = ~0u;

// How the robot's steps are fitted while a prediction looks ahead (measured on robust.yaml's
// tables, docs/notes/tuning.md): a step's weight halves after about 140 steps (3 s at 50 Hz);
// the pull towards the model counts as much as a few steps of a balancing pole; the estimate takes
// 70 % of each new reading (30 % and 50 % held all_at_once less often, 80 % no better).
constexpr double kFitForgetting = 0.995;
constexpr double kFitPullToModel = 1e-3;
constexpr double kFitLowest = 0.5;
constexpr double kFitHighest = 2.0;
constexpr double kObserverGain = 0.7;

// The fitted step's gains for one velocity (x_dot or theta_dot): its change over a step is
// gravity * (the model's change with no force) + force * (what the model's force adds).
struct StepFit
{
  double gravity = 1.0;
  double force = 1.0;
};

class DelayPredictor
{
public:
  // model: the physics the table learnt (its equations, the command clamped to its force_mag).
  // steps: how many steps late the robot carries a command out, <= kMaxPredictedDelaySteps (0:
  // predict() returns what it is given), or kDelayFoundFromStates. Throws std::invalid_argument
  // otherwise.
  DelayPredictor(const CartPoleParams& model, unsigned steps);

  // The steps predicted now: the told delay, or the one found so far (0 before one is).
  unsigned steps() const;
  bool finding() const
  {
    return estimator_.has_value();
  }
  // The delay found so far (finding() only): none before the states tell it.
  std::optional<unsigned> found() const
  {
    return estimator_ ? estimator_->estimate() : std::nullopt;
  }
  // An episode begins at `start`: nothing in flight but zero commands (the robot was stopped, or
  // a start waited with the command at 0).
  void begin(const CartPoleState& start);
  // The state observed now (what finds the delay; a told one needs none).
  void observed(const CartPoleState& state);
  // The command just sent to the robot.
  void sent(double effort);
  // The state when the next command sent will act: `observed` (the estimate, when `observed` is
  // the state last given to observed()) advanced by the fitted model under each command in
  // flight, oldest first. `observed` itself while steps() is 0.
  CartPoleState predict(const CartPoleState& observed) const;

  // The fitted gains of the cart's velocity ([0]) and the pole's ([1]): 1 and 1 until the robot's
  // steps say otherwise (and while steps() is 0, when nothing is predicted).
  const std::array<StepFit, 2>& fit() const
  {
    return gains_;
  }

private:
  // The command that acted over the step just observed (the one sent steps() before the newest).
  double actedCommand() const;
  // One step of the model with the fitted gains.
  CartPoleState fittedStep(const CartPoleState& state, double force) const;
  // Forgets the fit and starts the estimate from `state` (an episode's start, a new delay).
  void restartFit(const CartPoleState& state);

  CartPoleDynamics model_;
  unsigned told_ = 0;
  std::optional<DelayEstimator> estimator_;
  std::vector<double> sent_;  // a ring of the last commands, the newest at newest_
  std::size_t newest_ = 0;
  // The fit: for each velocity, decayed sums of z0 * z0, z0 * zf, zf * zf, z0 * y, zf * y (z0 the
  // model's change with no force, zf what its force adds, y the robot's change).
  std::array<std::array<double, 5>, 2> sums_{};
  std::array<StepFit, 2> gains_{};
  unsigned fitted_for_ = 0;            // the steps() the fit and the estimate were made under
  std::optional<CartPoleState> last_;  // the state last observed (none before an episode)
  CartPoleState estimate_ = CartPoleState::Zero();
};

}  // namespace cartpole_qlearning
