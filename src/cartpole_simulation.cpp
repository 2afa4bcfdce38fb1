#include "cartpole_qlearning/cartpole_simulation.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
CartPoleSimulation::CartPoleSimulation(const CartPoleParams& params, double start_state_bound, std::uint64_t seed)
  : dynamics_(params), start_state_bound_(start_state_bound), rng_(seed, kEnvironmentStream)
{
  if (!(std::isfinite(start_state_bound) && start_state_bound >= 0.0))
    throw std::invalid_argument("start_state_bound = " + std::to_string(start_state_bound) +
                                " is not allowed (must be finite and >= 0)");
}

const CartPoleState& CartPoleSimulation::resetRandom()
{
  for (int i = 0; i < 4; ++i)
    state_[i] = rng_.uniform(-start_state_bound_, start_state_bound_);
  applied_force_ = 0.0;
  return state_;
}

const CartPoleState& CartPoleSimulation::reset(const CartPoleState& state)
{
  state_ = state;
  applied_force_ = 0.0;
  return state_;
}

const CartPoleState& CartPoleSimulation::step(double force)
{
  applied_force_ = dynamics_.clampForce(force);
  state_ = dynamics_.step(state_, applied_force_);
  return state_;
}

}  // namespace cartpole_qlearning
