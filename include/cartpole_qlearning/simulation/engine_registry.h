// Every physics engine, described once: its name (physics/engine), the physics keys it takes, the
// joints it names, what its episodes and loading allow, and how it is made. The config's readers and
// writer, the sim node, the robustness suite and the controller's settings ask this registry and never
// which engine it is. Adding an engine: its own files, one line in engine_registry.cpp, and CMake.
// Built into the engines' library (cartpole_qlearning_engines), which the layers above link.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/simulation/physics_engine.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// A physics key an engine alone takes, and where its value goes: one of the three members.
struct EngineKey
{
  std::string name;                              // under physics/
  double CartPoleParams::*number = nullptr;      // a number of the equations' parameters
  Integrator CartPoleParams::*choice = nullptr;  // the integrator, by name
  std::string EngineParams::*text = nullptr;     // a text of the engine's (written quoted)
  // For a text that names a file, what it is ("an MJCF file"): ${VARIABLES} in it are expanded, a
  // relative path is the config file's folder's, and the engine needs it. Empty: not a file.
  std::string file;
  // A number a table's trained_with leaves out at its default (CartPoleParams()'s), so that the
  // tables of configs from before the key stay as they were.
  bool omitted_at_default = false;
};

struct EngineDescription
{
  std::string name;  // physics/engine's value
  // The physics keys it alone takes, in the order a table's trained_with writes them (after
  // physics/engine, before the keys every engine takes: force_mag, tau, start_state_bound). Another
  // engine's keys are refused beside it.
  std::vector<EngineKey> keys;
  // Why another engine's key is refused beside this one ("the model sets it: edit the model"); empty:
  // the other engine's own_keys_note says it.
  std::string foreign_keys_note;
  // What its keys are, when another engine refuses one and says nothing of its own ("it names a
  // MuJoCo model's parts").
  std::string own_keys_note;
  // Its model names the cart's and the pole's joints (EngineParams::cart_joint, pole_joint): the sim
  // publishes those, and the controller takes them by default. False: the URDF's (cart_joint, pole_joint).
  bool names_joints = false;
  // perturbations/half_length can scale its pole (a model's pole is its geometry: not).
  bool scales_half_length = false;
  // An episode is the same whatever ran before it: a reset leaves nothing of the last episode and
  // its steps draw no random numbers, so a suite may run single episodes out of order
  // (robustness_suite.h's episodesRunInAnyOrder). False unless shown.
  bool episodes_independent = false;
  // Engines may be made on several threads at once (the suite's cases run side by side). MuJoCo's
  // XML loading is not documented as thread-safe.
  bool makes_in_parallel = false;
  // What the sim's start line says of it: "integrator euler", "MuJoCo model /path/cartpole.xml".
  std::function<std::string(const CartPoleParams& physics, const EngineParams& engine)> describe;
  // Makes the engine stepped at physics.tau (how it loads: the equations at once, MuJoCo's library
  // the first time a config asks for it). Throws EngineError: a model that cannot serve, an engine
  // this build lacks.
  std::function<std::unique_ptr<PhysicsEngine>(const CartPoleParams& physics, const EngineParams& engine)> make;
};

// Every engine, in the order the registry lists them.
const std::vector<EngineDescription>& engineDescriptions();

// The engine of that name; throws std::invalid_argument naming the allowed ones otherwise.
const EngineDescription& engineNamed(const std::string& name);

// The engine the params ask for (engineNamed(params.name)).
inline const EngineDescription& engineOf(const EngineParams& params)
{
  return engineNamed(params.name);
}

}  // namespace cartpole_qlearning
