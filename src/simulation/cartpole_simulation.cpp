#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
CartPoleSimulation::CartPoleSimulation(const CartPoleParams& params, double start_state_bound, std::uint64_t seed,
                                       const PerturbationParams& perturbations)
  : CartPoleSimulation(std::make_unique<EquationsEngine>(params), start_state_bound, seed, perturbations)
{
}

CartPoleSimulation::CartPoleSimulation(std::unique_ptr<PhysicsEngine> engine, double start_state_bound,
                                       std::uint64_t seed, const PerturbationParams& perturbations)
  : engine_(std::move(engine)),
    equations_(dynamic_cast<EquationsEngine*>(engine_.get())),
    start_(StartDistribution::uniform(start_state_bound)),
    perturbations_(perturbations),
    noisy_(perturbations.noisy()),
    pushes_(perturbations.pushes()),
    rng_(seed, kEnvironmentStream),
    noise_rng_(seed, kNoiseStream),
    perturbation_rng_(seed, kPerturbationStream),
    delay_(perturbations.delay_steps)
{
  if (!engine_)
    throw std::invalid_argument("CartPoleSimulation: no engine");
  if (!(std::isfinite(start_state_bound) && start_state_bound >= 0.0))
    throw std::invalid_argument("start_state_bound = " + std::to_string(start_state_bound) +
                                " is not allowed (must be finite and >= 0)");
  const std::string error = perturbations.validate();
  if (!error.empty())
    throw std::invalid_argument("perturbations: " + error);
  if (perturbations.half_length.varies() && equations_ == nullptr)
    throw std::invalid_argument(
        "perturbations: half_length is not allowed with this engine (a model's pole is its geometry: "
        "scale it in the model)");
}

CartPoleSimulation::CartPoleSimulation(const CartPoleSimulation& other)
  : engine_(other.engine_->clone()),
    equations_(dynamic_cast<EquationsEngine*>(engine_.get())),
    start_(other.start_),
    perturbations_(other.perturbations_),
    noisy_(other.noisy_),
    pushes_(other.pushes_),
    rng_(other.rng_),
    noise_rng_(other.noise_rng_),
    perturbation_rng_(other.perturbation_rng_),
    delay_(other.delay_),
    observation_(other.observation_),
    applied_force_(other.applied_force_),
    motor_factor_(other.motor_factor_),
    last_push_(other.last_push_)
{
}

CartPoleSimulation& CartPoleSimulation::operator=(const CartPoleSimulation& other)
{
  if (this != &other)
    *this = CartPoleSimulation(other);
  return *this;
}

const CartPoleDynamics& CartPoleSimulation::dynamics() const
{
  if (equations_ == nullptr)
    throw std::logic_error("CartPoleSimulation::dynamics: the engine is not the equations");
  return equations_->dynamics();
}

void CartPoleSimulation::beginEpisode()
{
  applied_force_ = 0.0;
  last_push_ = 0.0;
  unsigned delay = perturbations_.delay_steps;
  if (perturbations_.drawnPerEpisode())
  {
    const EpisodeFactors factors = drawEpisodeFactors(perturbations_, perturbation_rng_, delay);
    motor_factor_ = factors.motor;
    engine_->setFactors(factors);
  }
  delay_.reset(delay);
  const CartPoleState& state = engine_->state();
  observation_ = noisy_ ? addSensorNoise(state, perturbations_, noise_rng_) : state;
}

void CartPoleSimulation::setStart(const StartDistribution& start)
{
  for (std::size_t i = 0; i < kStateDimensions; ++i)
    if (!(std::isfinite(start.centre[i]) && std::isfinite(start.spread[i]) && start.spread[i] >= 0.0))
      throw std::invalid_argument(std::string("start of ") + stateDimensionName(i) + ": centre " +
                                  std::to_string(start.centre[i]) + ", spread " + std::to_string(start.spread[i]) +
                                  " is not allowed (must be finite, spread >= 0)");
  start_ = start;
}

const CartPoleState& CartPoleSimulation::resetRandom()
{
  CartPoleState start;
  for (std::size_t i = 0; i < kStateDimensions; ++i)
  {
    const double spread = start_.spread[i];
    start[i] = start_.centre[i] + (start_.normal[i] ? spread * rng_.normal() : rng_.uniform(-spread, spread));
  }
  return reset(start);
}

const CartPoleState& CartPoleSimulation::reset(const CartPoleState& state)
{
  engine_->setState(state);
  beginEpisode();
  return engine_->state();
}

const CartPoleState& CartPoleSimulation::step(double command)
{
  last_push_ = 0.0;
  const double acting = delay_.apply(command);
  if (pushes_ && perturbation_rng_.uniform01() < perturbations_.push_probability)
    last_push_ = perturbation_rng_.uniform01() < 0.5 ? -perturbations_.push_force : perturbations_.push_force;
  // EquationsEngine is final: through its own pointer the step is inlined here.
  applied_force_ = equations_ != nullptr ? equations_->step(acting, last_push_) : engine_->step(acting, last_push_);
  const CartPoleState& state = equations_ != nullptr ? equations_->state() : engine_->state();
  observation_ = noisy_ ? addSensorNoise(state, perturbations_, noise_rng_) : state;
  return state;
}

}  // namespace cartpole_qlearning
