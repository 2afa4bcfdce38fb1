// The state a command will meet on a robot that carries commands out `steps` late (ros_control
// hardware answers a control period late: the command decided at state k acts from k + 1). A
// table learnt on a model without that delay decides for the state it sees; by the time its
// command acts, the robot has moved on under the commands sent before. Acting on the state the
// model predicts for that moment (the observed state advanced by the commands still in flight,
// oldest first) is the simplest Smith predictor. For a robot known to answer late: on one that
// does not, the prediction is that many steps wrong.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <cstddef>
#include <vector>

namespace cartpole_qlearning
{
// The most steps a prediction may look ahead (a second at 50 Hz).
constexpr unsigned kMaxPredictedDelaySteps = 50;

class DelayPredictor
{
public:
  // model: the physics the table learnt (its equations, the command clamped to its force_mag).
  // steps: how many steps late the robot carries a command out, <= kMaxPredictedDelaySteps;
  // 0: predict() returns what it is given. Throws std::invalid_argument otherwise.
  DelayPredictor(const CartPoleParams& model, unsigned steps);

  unsigned steps() const
  {
    return static_cast<unsigned>(in_flight_.size());
  }
  // An episode begins: nothing in flight but zero commands (the robot was stopped, or a start
  // waited with the command at 0).
  void begin();
  // The command just sent to the robot.
  void sent(double effort);
  // The state when the next command sent will act: `observed` advanced by the model under each
  // command in flight, oldest first.
  CartPoleState predict(const CartPoleState& observed) const;

private:
  CartPoleDynamics model_;
  std::vector<double> in_flight_;  // a ring: the oldest command at oldest_
  std::size_t oldest_ = 0;
};

}  // namespace cartpole_qlearning
