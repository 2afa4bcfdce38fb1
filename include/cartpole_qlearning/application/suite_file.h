// A robustness suite's file (config/robust_suite.yaml): its cases, each a set of conditions a
// real cart-pole meets (a late command, noisy sensors, other masses, a weaker motor, pushes, wider
// starts, all at once: perturbations.h), the episodes each runs and the balanced episodes each
// needs to pass. robustness_suite.h tells the rest.
#pragma once

#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/simulation/perturbations.h"
#include "cartpole_qlearning/simulation/physics_engine.h"

#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
struct SuiteCase
{
  std::string name;
  // The case's physics (the configuration's, with the case's physics keys over it) and start region.
  CartPoleParams physics;
  EngineParams engine;  // the configuration's, or the case's own (a case may name a model)
  double start_state_bound = 0.05;
  PerturbationParams perturbations;
  std::uint64_t pass = 95;  // balanced episodes (of the suite's episodes) needed to pass
};

struct RobustnessSuite
{
  std::string origin;            // the file, for messages
  std::uint64_t episodes = 100;  // per case
  std::uint64_t seed = 1000;     // the evaluation's own seed: start states, noise, draws, pushes
  // The suite's own criterion, whatever the training used: balanced means reaching this many
  // steps, from starts in +-start_state_bound (a case's physics/start_state_bound overrides it).
  unsigned max_episode_steps = 500;
  double start_state_bound = 0.05;
  std::vector<SuiteCase> cases;
};

// Reads a suite file (see config/robust_suite.yaml). base: the physics that the cases' keys
// override (the configuration the table was trained with; its step limit and start region play
// no part: the suite's own do). Throws ConfigError naming
// the case and key on a bad value or an unknown key.
RobustnessSuite parseRobustnessSuite(const std::string& yaml, const std::string& origin, const TrainingConfig& base);
RobustnessSuite loadRobustnessSuite(const std::string& path, const TrainingConfig& base);

// Whether a case's episodes can be run in any order: each episode's start and physics are drawn
// at its reset and its steps draw nothing (no sensor noise, no pushes; the equations' engine), so
// episode e is the same whatever the table did in the episodes before it. (A noisy case's
// episode e meets the noise drawn after every step of the episodes before it: run in order only.)
bool episodesRunInAnyOrder(const SuiteCase& suite_case);
}  // namespace cartpole_qlearning
