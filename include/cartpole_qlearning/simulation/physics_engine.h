// What steps the cart-pole: the equations written here (EquationsEngine) or a physics engine's
// model (MujocoEngine, in its own library). CartPoleSimulation keeps what every engine shares
// (the seeded start states, the actuation delay, the sensor noise, the draws of each episode's
// physics and of the pushes) and hands the engine only the physics: a state to start from, the
// episode's factors, and a command and a push to act for one tau.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
// Which engine (engine_registry.h describes each), and for a model's engine which model and which
// of its joints and actuator are the cart-pole's (the config's physics/engine, model, cart_joint,
// pole_joint, actuator).
struct EngineParams
{
  std::string name = "equations";     // physics/engine: a name engine_registry.h lists
  std::string model;                  // the MJCF file (an absolute path, or one relative to the working folder)
  std::string cart_joint = "slider";  // a slide joint: x and x_dot are its qpos and qvel
  std::string pole_joint = "hinge";   // a hinge joint on a body the cart carries: theta and theta_dot
  std::string actuator = "slide";     // a motor on cart_joint: an effort F is ctrl = F / gear
};

// A model that cannot serve as the cart-pole (it fails to load, a joint or actuator is missing
// or of the wrong kind, tau is not a whole number of its steps), or an engine this build lacks.
// The message names the config key and the model.
class EngineError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// Factors of one episode's physics over the configured (perturbations.h draws them): 1 is the
// configured physics.
struct EpisodeFactors
{
  double mass_cart = 1.0;
  double mass_pole = 1.0;
  double half_length = 1.0;
  double motor = 1.0;  // scales the force a command gives, after the drive's clamp
};

class PhysicsEngine
{
public:
  virtual ~PhysicsEngine() = default;
  virtual std::unique_ptr<PhysicsEngine> clone() const = 0;

  // [s] one step of the simulation (the config's physics/tau).
  virtual double tau() const = 0;
  // The largest force the drive gives [N] (commands beyond it are clamped).
  virtual double forceLimit() const = 0;
  // This episode's physics: the configured one with the factors applied.
  virtual void setFactors(const EpisodeFactors& factors) = 0;
  // Puts the cart-pole in this state (x [m], x_dot [m/s], theta [rad, positive leaning toward +x],
  // theta_dot [rad/s]), at rest otherwise.
  virtual void setState(const CartPoleState& state) = 0;
  // Advances one tau: the command [N] clamped to the drive's limit, times the motor factor, with
  // `push` [N] on the cart along +x. Returns the force that acted on the cart along x [N].
  virtual double step(double command, double push) = 0;
  virtual const CartPoleState& state() const = 0;
  // Steps whose command the drive clamped, since the engine was made.
  virtual std::uint64_t clamps() const = 0;
  // The names of the cart's and the pole's bodies (a model's own; the URDF's links, cart and pole,
  // for the equations): the sim's TF frames unless it is told others.
  virtual std::string cartBody() const
  {
    return "cart";
  }
  virtual std::string poleBody() const
  {
    return "pole";
  }
};

// CartPole-v1's equations (cartpole_dynamics.h) as an engine. Final, with step() inline: a
// simulation that knows its engine is this one steps it without a virtual call.
class EquationsEngine final : public PhysicsEngine
{
public:
  explicit EquationsEngine(const CartPoleParams& params);

  std::unique_ptr<PhysicsEngine> clone() const override
  {
    return std::make_unique<EquationsEngine>(*this);
  }
  double tau() const override
  {
    return dynamics_.params().tau;
  }
  double forceLimit() const override
  {
    return dynamics_.params().force_mag;
  }
  void setFactors(const EpisodeFactors& factors) override;
  void setState(const CartPoleState& state) override
  {
    state_ = state;
  }
  double step(double command, double push) override
  {
    // The clamp is the configured force_mag's (the drive's limit); a weaker motor gives less of it.
    const double clamped = dynamics_.clampForce(command);
    clamps_ += clamped != command;
    double force = motor_factor_ * clamped;
    if (push != 0.0)
      force += push;
    state_ = dynamics_.step(state_, force);
    return force;
  }
  const CartPoleState& state() const override
  {
    return state_;
  }
  std::uint64_t clamps() const override
  {
    return clamps_;
  }
  // This episode's equations.
  const CartPoleDynamics& dynamics() const
  {
    return dynamics_;
  }

private:
  CartPoleParams nominal_;
  CartPoleDynamics dynamics_;
  CartPoleState state_ = CartPoleState::Zero();
  double motor_factor_ = 1.0;
  std::uint64_t clamps_ = 0;
};

}  // namespace cartpole_qlearning
