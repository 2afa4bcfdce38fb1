#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
CartPoleSimulation::CartPoleSimulation(const CartPoleParams& params, double start_state_bound, std::uint64_t seed,
                                       const PerturbationParams& perturbations)
  : nominal_(params),
    dynamics_(params),
    start_state_bound_(start_state_bound),
    perturbations_(perturbations),
    rng_(seed, kEnvironmentStream),
    noise_rng_(seed, kNoiseStream),
    perturbation_rng_(seed, kPerturbationStream),
    delay_(perturbations.delay_steps)
{
  if (!(std::isfinite(start_state_bound) && start_state_bound >= 0.0))
    throw std::invalid_argument("start_state_bound = " + std::to_string(start_state_bound) +
                                " is not allowed (must be finite and >= 0)");
  const std::string error = perturbations.validate();
  if (!error.empty())
    throw std::invalid_argument("perturbations: " + error);
}

void CartPoleSimulation::beginEpisode()
{
  applied_force_ = 0.0;
  last_push_ = 0.0;
  unsigned delay = perturbations_.delay_steps;
  if (perturbations_.mass_cart.varies() || perturbations_.mass_pole.varies() || perturbations_.half_length.varies() ||
      perturbations_.motor.varies() || perturbations_.delay_steps_max != perturbations_.delay_steps)
    dynamics_ = CartPoleDynamics(drawEpisodePhysics(nominal_, perturbations_, perturbation_rng_, motor_factor_, delay));
  delay_.reset(delay);
  observation_ = perturbations_.noisy() ? addSensorNoise(state_, perturbations_, noise_rng_) : state_;
}

const CartPoleState& CartPoleSimulation::resetRandom()
{
  for (int i = 0; i < 4; ++i)
    state_[i] = rng_.uniform(-start_state_bound_, start_state_bound_);
  beginEpisode();
  return state_;
}

const CartPoleState& CartPoleSimulation::reset(const CartPoleState& state)
{
  state_ = state;
  beginEpisode();
  return state_;
}

const CartPoleState& CartPoleSimulation::step(double command)
{
  // The clamp is the configured force_mag's (the drive's limit); a weaker motor gives less of it.
  applied_force_ = motor_factor_ * dynamics_.clampForce(delay_.apply(command));
  last_push_ = 0.0;
  if (perturbations_.push_probability > 0.0 && perturbations_.push_force != 0.0 &&
      perturbation_rng_.uniform01() < perturbations_.push_probability)
  {
    last_push_ = perturbation_rng_.uniform01() < 0.5 ? -perturbations_.push_force : perturbations_.push_force;
    applied_force_ += last_push_;
  }
  state_ = dynamics_.step(state_, applied_force_);
  observation_ = perturbations_.noisy() ? addSensorNoise(state_, perturbations_, noise_rng_) : state_;
  return state_;
}

}  // namespace cartpole_qlearning
