// Reading and validating the physics, task, learning and training parameters. One reader
// serves both the YAML file (train_headless) and the ROS parameter server (the nodes), so a
// key means the same thing, and is checked the same way, wherever it is set.
#pragma once

#include "cartpole_qlearning/cartpole_dynamics.h"
#include "cartpole_qlearning/cartpole_task.h"
#include "cartpole_qlearning/q_learning_agent.h"

#include <cstdint>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// A bad key or value. The message names the key, the value and what is allowed.
class ConfigError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// Where parameters come from. Keys are slash-separated paths such as "learning/gamma".
// Each get() returns false when the key is absent and throws ConfigError when it is present
// with a value of the wrong type.
class ParameterSource
{
public:
  virtual ~ParameterSource() = default;
  virtual bool get(const std::string& key, double& value) const = 0;
  virtual bool get(const std::string& key, std::int64_t& value) const = 0;
  virtual bool get(const std::string& key, bool& value) const = 0;
  virtual bool get(const std::string& key, std::string& value) const = 0;
  virtual bool get(const std::string& key, std::vector<double>& value) const = 0;
  // Every leaf key present below a section ("learning" -> "learning/gamma", "learning/epsilon/min", ...).
  virtual std::vector<std::string> keysUnder(const std::string& section) const = 0;
  // Where the parameters come from, for messages ("config/cartpole.yaml", "/cartpole").
  virtual std::string origin() const = 0;
};

// The value of a key, or fallback when it is absent (a wrong type still throws ConfigError).
template <typename T>
T valueOr(const ParameterSource& source, const std::string& key, T fallback)
{
  source.get(key, fallback);
  return fallback;
}

// A YAML document as a parameter source. Throws ConfigError when the file cannot be read or parsed.
std::unique_ptr<ParameterSource> loadYamlParameters(const std::string& path);
std::unique_ptr<ParameterSource> parseYamlParameters(const std::string& text, const std::string& origin);

// Refuses top-level keys other than the sections physics, task, learning and training (for a
// file that holds only those; the parameter server holds other names beside them).
void refuseUnknownSections(const ParameterSource& source);

struct TrainingLimits
{
  std::uint64_t max_episodes = 1000;  // stop after this many episodes, solved or not
  bool stop_when_solved = true;       // stop at the first solved episode
  std::uint64_t progress_every = 50;  // a progress line every this many episodes (0: none)

  // Whether training ends after the episode that made `episodes` in all, `solved` or not.
  bool reached(std::uint64_t episodes, bool solved) const
  {
    return (solved && stop_when_solved) || episodes >= max_episodes;
  }
};

struct TrainingConfig
{
  CartPoleParams physics;
  double start_state_bound = 0.05;  // [m, m/s, rad, rad/s] random starts are uniform in +-this
  TaskParams task;
  AgentParams agent;
  TrainingLimits limits;
};

// Each reader starts from the defaults, overrides what the source sets, validates, and throws
// ConfigError naming the key on a bad value or an unknown key in its section.
void readPhysics(const ParameterSource& source, CartPoleParams& physics, double& start_state_bound);
TaskParams readTask(const ParameterSource& source);
AgentParams readAgent(const ParameterSource& source);
TrainingLimits readLimits(const ParameterSource& source);
TrainingConfig readTrainingConfig(const ParameterSource& source);

}  // namespace cartpole_qlearning
