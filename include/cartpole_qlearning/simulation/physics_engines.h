// The engine a config asks for (physics/engine), made as the registry (engine_registry.h) says.
// Built with the registry as its own library (cartpole_qlearning_engines) that links the simulation
// layer and, when the build found MuJoCo, loads cartpole_qlearning_mujoco (built beside it) the first
// time a config asks for MuJoCo (mujoco_loader.cpp); the layers above link it, and the simulation
// layer itself never links MuJoCo. Without MuJoCo, asking for it throws EngineError saying how to
// get it.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/simulation/physics_engine.h"

#include <cstdint>
#include <memory>

namespace cartpole_qlearning
{
// Whether this build has the MuJoCo engine.
bool mujocoAvailable();

// The engine `engine` names, with `physics` (the equations') stepped at physics.tau. Throws
// EngineError (a model that cannot serve, an engine this build lacks), std::invalid_argument for a
// name the registry does not list.
std::unique_ptr<PhysicsEngine> makePhysicsEngine(const CartPoleParams& physics, const EngineParams& engine);

// A simulation on that engine (CartPoleSimulation's constructors say the rest). Throws
// EngineError, or std::invalid_argument for perturbations the engine cannot apply.
CartPoleSimulation makeSimulation(const CartPoleParams& physics, const EngineParams& engine, double start_state_bound,
                                  std::uint64_t seed, const PerturbationParams& perturbations = PerturbationParams());

}  // namespace cartpole_qlearning
