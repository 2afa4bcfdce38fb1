// The simulated robot: dynamics, the current state, and the seeded draw of start states.
// The simulator node owns one; the headless trainer owns one in the same way.
#pragma once

#include "cartpole_qlearning/cartpole_dynamics.h"
#include "cartpole_qlearning/random.h"

#include <cstdint>

namespace cartpole_qlearning
{
class CartPoleSimulation
{
public:
  // start_state_bound: a random reset draws each state value uniformly in +-this.
  CartPoleSimulation(const CartPoleParams& params, double start_state_bound, std::uint64_t seed);

  const CartPoleDynamics& dynamics() const
  {
    return dynamics_;
  }
  const CartPoleState& state() const
  {
    return state_;
  }
  // The force applied during the last step [N], after clamping.
  double appliedForce() const
  {
    return applied_force_;
  }

  // Draws x, x_dot, theta, theta_dot in that order from the environment stream.
  const CartPoleState& resetRandom();
  const CartPoleState& reset(const CartPoleState& state);

  // Advances one tau with the force clamped to +-force_mag.
  const CartPoleState& step(double force);

private:
  CartPoleDynamics dynamics_;
  double start_state_bound_;
  RandomStream rng_;
  CartPoleState state_ = CartPoleState::Zero();
  double applied_force_ = 0.0;
};

}  // namespace cartpole_qlearning
