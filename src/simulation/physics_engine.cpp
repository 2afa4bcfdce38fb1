#include "cartpole_qlearning/simulation/physics_engine.h"

#include "cartpole_qlearning/simulation/engine_registry.h"

#include <cmath>

namespace cartpole_qlearning
{
// CartPole-v1's equations (engine_registry.h): its own keys are CartPoleParams' (cartpole_dynamics.h).
EngineDescription equationsEngineDescription()
{
  EngineDescription d;
  d.name = "equations";
  for (const auto& [name, number] :
       {std::pair<const char*, double CartPoleParams::*>{"gravity", &CartPoleParams::gravity},
        {"mass_cart", &CartPoleParams::mass_cart},
        {"mass_pole", &CartPoleParams::mass_pole},
        {"half_length", &CartPoleParams::half_length}})
    d.keys.push_back(EngineKey{name, number, nullptr, nullptr, ""});
  d.keys.push_back(EngineKey{"integrator", nullptr, &CartPoleParams::integrator, nullptr, ""});
  d.keys.push_back(EngineKey{"cart_friction", &CartPoleParams::cart_friction, nullptr, nullptr, ""});
  d.keys.push_back(EngineKey{"pole_friction", &CartPoleParams::pole_friction, nullptr, nullptr, ""});
  d.keys.push_back(EngineKey{"rail_limit", &CartPoleParams::rail_limit, nullptr, nullptr, "", true});
  d.scales_half_length = true;
  d.episodes_independent = true;
  d.makes_in_parallel = true;
  d.describe = [](const CartPoleParams& physics, const EngineParams&) {
    return "integrator " + toString(physics.integrator);
  };
  d.make = [](const CartPoleParams& physics, const EngineParams&) -> std::unique_ptr<PhysicsEngine> {
    return std::make_unique<EquationsEngine>(physics);
  };
  return d;
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
