#include "cartpole_qlearning/simulation/physics_engine.h"

#include <cmath>

namespace cartpole_qlearning
{
EngineKind engineKindFromString(const std::string& name)
{
  if (name == "equations")
    return EngineKind::Equations;
  if (name == "mujoco")
    return EngineKind::Mujoco;
  throw std::invalid_argument("unknown engine '" + name + "' (allowed: equations, mujoco)");
}

std::string toString(EngineKind kind)
{
  return kind == EngineKind::Mujoco ? "mujoco" : "equations";
}

EquationsEngine::EquationsEngine(const CartPoleParams& params) : nominal_(params), dynamics_(params) {}

void EquationsEngine::setFactors(const EpisodeFactors& factors)
{
  CartPoleParams physics = nominal_;
  physics.mass_cart = nominal_.mass_cart * factors.mass_cart;
  physics.mass_pole = nominal_.mass_pole * factors.mass_pole;
  physics.half_length = nominal_.half_length * factors.half_length;
  dynamics_ = CartPoleDynamics(physics);
  motor_factor_ = factors.motor;
}

}  // namespace cartpole_qlearning
