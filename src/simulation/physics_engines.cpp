#include "cartpole_qlearning/simulation/physics_engines.h"

#include "cartpole_qlearning/simulation/engine_registry.h"

namespace cartpole_qlearning
{
std::unique_ptr<PhysicsEngine> makePhysicsEngine(const CartPoleParams& physics, const EngineParams& engine)
{
  return engineOf(engine).make(physics, engine);
}

CartPoleSimulation makeSimulation(const CartPoleParams& physics, const EngineParams& engine, double start_state_bound,
                                  std::uint64_t seed, const PerturbationParams& perturbations)
{
  return CartPoleSimulation(makePhysicsEngine(physics, engine), start_state_bound, seed, perturbations);
}

}  // namespace cartpole_qlearning
