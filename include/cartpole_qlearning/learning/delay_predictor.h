// The state a command will meet on a robot that carries commands out `steps` late (ros_control
// hardware answers a control period late: the command decided at state k acts from k + 1). A
// table learnt on a model without that delay decides for the state it sees; by the time its
// command acts, the robot has moved on under the commands sent before. Acting on the state the
// model predicts for that moment (the observed state advanced by the commands still in flight,
// oldest first) is the simplest Smith predictor. The delay is told (a number) or found from how
// the robot's states answer its commands (DelayEstimator): until it is found, and on a robot
// found prompt, the prediction is the observed state.
#pragma once

#include "cartpole_qlearning/learning/delay_estimator.h"
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <cstddef>
#include <optional>
#include <vector>

namespace cartpole_qlearning
{
// The most steps a prediction may look ahead (a second at 50 Hz).
constexpr unsigned kMaxPredictedDelaySteps = 50;
// As a number of steps: the delay is found from the states (DelayEstimator), not told.
constexpr unsigned kDelayFoundFromStates = ~0u;

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
  // The state when the next command sent will act: `observed` advanced by the model under each
  // command in flight, oldest first.
  CartPoleState predict(const CartPoleState& observed) const;

private:
  CartPoleDynamics model_;
  unsigned told_ = 0;
  std::optional<DelayEstimator> estimator_;
  std::vector<double> sent_;  // a ring of the last commands, the newest at newest_
  std::size_t newest_ = 0;
};

}  // namespace cartpole_qlearning
