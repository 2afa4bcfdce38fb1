#include "cartpole_qlearning/simulation/physics_engines.h"

#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
#include "cartpole_qlearning/simulation/mujoco_engine.h"
#endif

namespace cartpole_qlearning
{
bool mujocoAvailable()
{
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
  return true;
#else
  return false;
#endif
}

std::unique_ptr<PhysicsEngine> makePhysicsEngine(const CartPoleParams& physics, const EngineParams& engine)
{
  if (engine.kind == EngineKind::Equations)
    return std::make_unique<EquationsEngine>(physics);
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
  return std::make_unique<MujocoEngine>(engine, physics.tau);
#else
  throw EngineError(
      "physics/engine = 'mujoco' is not available: cartpole_qlearning was built without MuJoCo. "
      "Install it (Debian 12: sudo apt-get install libmujoco-dev, or scripts/setup.sh), then "
      "rebuild (catkin_make): CMake finds it and builds the MuJoCo engine");
#endif
}

CartPoleSimulation makeSimulation(const CartPoleParams& physics, const EngineParams& engine, double start_state_bound,
                                  std::uint64_t seed, const PerturbationParams& perturbations)
{
  return CartPoleSimulation(makePhysicsEngine(physics, engine), start_state_bound, seed, perturbations);
}

}  // namespace cartpole_qlearning
