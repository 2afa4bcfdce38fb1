// The simulated robot: a physics engine (physics_engine.h: the equations, or a MuJoCo model), the
// seeded draw of start states, and what a real cart-pole does beside the ideal model
// (perturbations.h: a late command, noisy sensors, other masses per episode, pushes). The
// simulator node owns one; the headless trainer owns one in the same way. physics_engines.h
// makes one from a config's engine.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/simulation/perturbations.h"
#include "cartpole_qlearning/common/random.h"

#include <array>
#include <cstdint>
#include <memory>

namespace cartpole_qlearning
{
// How a random reset draws each state value (x, x_dot, theta, theta_dot): centre + spread x a
// standard normal draw where `normal`, else uniformly in centre +- spread.
struct StartDistribution
{
  CartPoleState centre = CartPoleState::Zero();
  CartPoleState spread = CartPoleState::Zero();
  std::array<bool, kStateDimensions> normal{};

  // Every value uniform in +-bound (CartPole-v1's starts).
  static StartDistribution uniform(double bound)
  {
    StartDistribution start;
    start.spread.fill(bound);
    return start;
  }
};

class CartPoleSimulation
{
public:
  // start_state_bound: a random reset draws each state value uniformly in +-this.
  // The equations (EquationsEngine) with these params.
  CartPoleSimulation(const CartPoleParams& params, double start_state_bound, std::uint64_t seed,
                     const PerturbationParams& perturbations = PerturbationParams());
  // Another engine (not null). Throws std::invalid_argument when a perturbation asks for what the
  // engine cannot do (half_length on a model whose geometry is its own).
  CartPoleSimulation(std::unique_ptr<PhysicsEngine> engine, double start_state_bound, std::uint64_t seed,
                     const PerturbationParams& perturbations = PerturbationParams());
  CartPoleSimulation(const CartPoleSimulation& other);
  CartPoleSimulation& operator=(const CartPoleSimulation& other);
  CartPoleSimulation(CartPoleSimulation&&) = default;
  CartPoleSimulation& operator=(CartPoleSimulation&&) = default;

  const PhysicsEngine& engine() const
  {
    return *engine_;
  }
  // This episode's equations (the configured physics, or the physics drawn for this episode).
  // The equations' engine only: throws std::logic_error with another.
  const CartPoleDynamics& dynamics() const;
  // The true state.
  const CartPoleState& state() const
  {
    return engine_->state();
  }
  // Steps whose command the drive clamped (to +-force_mag, or a model's ctrlrange), since construction.
  std::uint64_t clamps() const
  {
    return engine_->clamps();
  }
  // What the sensors read of it (the true state when they are not noisy): drawn once per reset
  // and step, so it reads the same however often it is asked.
  const CartPoleState& observation() const
  {
    return observation_;
  }
  // The force that acted during the last step [N]: the command that came through the delay,
  // clamped to the drive's limit, times this episode's motor factor, plus any push.
  double appliedForce() const
  {
    return applied_force_;
  }
  // This episode's motor factor (1 unless perturbations.motor varies).
  double motorFactor() const
  {
    return motor_factor_;
  }
  // This episode's actuation delay [steps].
  unsigned delaySteps() const
  {
    return delay_.steps();
  }
  // The push that acted during the last step [N] (0: none).
  double lastPush() const
  {
    return last_push_;
  }
  const PerturbationParams& perturbations() const
  {
    return perturbations_;
  }

  // Where resetRandom starts (by default each value uniform in +-start_state_bound). Throws
  // std::invalid_argument on a spread that is negative or not finite.
  void setStart(const StartDistribution& start);
  const StartDistribution& start() const
  {
    return start_;
  }
  // A new episode: draws x, x_dot, theta, theta_dot in that order from the environment stream
  // (start()), then this episode's physics (when the perturbations vary it). Returns the true state.
  const CartPoleState& resetRandom();
  // A new episode from the given state (physics drawn as resetRandom does).
  const CartPoleState& reset(const CartPoleState& state);

  // Advances one tau: the command joins the actuation delay, and the one that comes out of it
  // acts (clamped to +-force_mag, times the motor factor, plus a push when one is drawn).
  // Returns the true state.
  const CartPoleState& step(double command);

private:
  void beginEpisode();

  std::unique_ptr<PhysicsEngine> engine_;
  // engine_ when it is the equations (else null): stepped without a virtual call. It points into
  // the engine's own heap object, so a moved simulation keeps it valid.
  EquationsEngine* equations_ = nullptr;
  StartDistribution start_;
  PerturbationParams perturbations_;
  // What the perturbations ask of every step, worked out once.
  bool noisy_ = false;
  bool pushes_ = false;
  RandomStream rng_;
  RandomStream noise_rng_;
  RandomStream perturbation_rng_;
  ActuationDelay delay_;
  CartPoleState observation_ = CartPoleState::Zero();
  double applied_force_ = 0.0;
  double motor_factor_ = 1.0;
  double last_push_ = 0.0;
};

}  // namespace cartpole_qlearning
