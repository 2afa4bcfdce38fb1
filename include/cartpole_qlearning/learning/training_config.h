// The configuration: the physics, perturbations, task, learning and training sections, each a table
// of its keys (config/config_section.h) that reads, checks, refuses unknown keys and writes. One
// reader serves both the YAML file (train_headless) and the ROS parameter server (the nodes), so a
// key means the same thing, and is checked the same way, wherever it is set.
#pragma once

#include "cartpole_qlearning/config/config_section.h"
#include "cartpole_qlearning/io/yaml_parameters.h"  // the sources and the sink the readers and writer take

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/discretiser.h"
#include "cartpole_qlearning/simulation/perturbations.h"
#include "cartpole_qlearning/simulation/physics_engine.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The state's four values as one list key (bins, bounds, noise): exactly 4 numbers, whole ones in
// [1, kMaxBinsPerDimension] when `whole`.
template <typename T>
void readDimensions(SectionReader& reader, const std::string& name, std::array<T, kStateDimensions>& values, bool whole)
{
  reader.readList(name, values, "x, x_dot, theta, theta_dot", whole ? kMaxBinsPerDimension : 0);
}

// Refuses top-level keys other than the sections physics, perturbations, task, learning and training (for a
// file that holds only those; the parameter server holds other names beside them).
void refuseUnknownSections(const ParameterSource& source);

// What ends training: the first solved episode, or the first greedy evaluation of the robustness
// suite that passes (the run application evaluates it; training/until).
enum class TrainUntil
{
  Solved,
  SuitePasses
};

struct TrainingLimits
{
  std::uint64_t max_episodes = 1000;  // stop after this many episodes, solved or not
  bool stop_when_solved = true;       // stop at the first solved episode (until solved)
  std::uint64_t progress_every = 50;  // a progress line every this many episodes (0: none)
  // The robustness suite a run's final table is judged on (robustness_suite.h): a file, relative
  // to the folders RunSettings::suite_folders lists; "none": no suite.
  std::string suite = "robust_suite.yaml";
  std::uint64_t suite_every = 0;  // [episodes] also evaluate it during training, keeping the best table (0: never)
  // [episodes] the evaluations during training that look for the best table (one that could beat
  // it is judged whole): every one (0), or those at multiples of this; the others only ask whether
  // the table passes, which is all until suite_passes needs, for a fraction of the greedy steps.
  std::uint64_t best_every = 0;
  TrainUntil until = TrainUntil::Solved;

  // Training goes on after solved, to max_episodes (stop_when_solved false, until solved).
  bool goesOnAfterSolved() const
  {
    return until == TrainUntil::Solved && !stop_when_solved;
  }
  // Whether training ends after the episode that made `episodes` in all, `solved` or not (a
  // suite that passes ends it too: the run application decides that).
  bool reached(std::uint64_t episodes, bool solved) const
  {
    return (solved && stop_when_solved && until == TrainUntil::Solved) || episodes >= max_episodes;
  }
};

struct TrainingConfig
{
  CartPoleParams physics;
  EngineParams engine;               // physics/engine and, for MuJoCo, its model, joints and actuator
  double start_state_bound = 0.05;   // [m, m/s, rad, rad/s] random starts are uniform in +-this
  PerturbationParams perturbations;  // what a real cart-pole does (none by default)
  TaskParams task;
  AgentParams agent;
  TrainingLimits limits;
};

// The physics section's values (TrainingConfig holds them apart).
struct PhysicsSection
{
  CartPoleParams physics;
  EngineParams engine;
  double start_state_bound = 0.05;
};

// Each section's table of keys, in the order a table's trained_with writes them. The physics
// section's engine keys are the engines' own (engine_registry.h: each written only beside its
// engine), the perturbations' are perturbationKeys() (perturbations.h).
const ConfigSection<PhysicsSection>& physicsSection();
const ConfigSection<PerturbationParams>& perturbationsSection();
const ConfigSection<TaskParams>& taskSection();
const ConfigSection<AgentParams>& learningSection();
const ConfigSection<TrainingLimits>& trainingSection();
// Every key of the five sections ("physics/engine", ..., "training/until"): what docs/configuration.md lists.
std::vector<std::string> configKeys();

// Each reader starts from the defaults, overrides what the source sets, validates, and throws
// ConfigError naming the key on a bad value or an unknown key in its section.
// The physics section with the engine's keys: engine (equations or mujoco), and for mujoco model (an MJCF
// file: absolute, or relative to source.folder(); ${NAME} is the environment variable NAME),
// cart_joint, pole_joint and actuator. The equations' own keys (gravity, masses, half_length,
// integrator, friction) are refused beside engine mujoco, the model's keys beside the equations.
// (The model itself is read when a simulation is made: physics_engines.h.)
void readPhysics(const ParameterSource& source, CartPoleParams& physics, double& start_state_bound,
                 EngineParams& engine);
// The perturbations section (a late command, sensor noise, physics drawn per episode, pushes).
PerturbationParams readPerturbations(const ParameterSource& source);
// Refuses perturbations the engine cannot apply (half_length beside a MuJoCo model), naming the key.
void checkPerturbationsFitEngine(const ParameterSource& source, const EngineParams& engine,
                                 const PerturbationParams& perturbations);
TaskParams readTask(const ParameterSource& source);
AgentParams readAgent(const ParameterSource& source);
TrainingLimits readLimits(const ParameterSource& source);
TrainingConfig readTrainingConfig(const ParameterSource& source);

// Whether the source sets any key of the sections physics, perturbations, task, learning and
// training (a config was loaded there), or leaves them all at their defaults.
bool holdsTrainingConfig(const ParameterSource& source);

// The configuration as a YAML document of those sections, every key with the value in use
// (defaults included, numbers exact): what a table says trained it (q_table.h's trained_with).
// parseYamlParameters and readTrainingConfig give the same configuration back, and the same
// configuration gives the same text however it was read (a file, the parameter server).
std::string trainingConfigText(const TrainingConfig& config);

// The shortest text that reads back as the same double, whatever the locale (the config text a
// table carries, and messages that must show two values apart however close they are).
std::string exactText(double value);

}  // namespace cartpole_qlearning
