// Reading and validating the physics, task, learning and training parameters. One reader
// serves both the YAML file (train_headless) and the ROS parameter server (the nodes), so a
// key means the same thing, and is checked the same way, wherever it is set.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/discretiser.h"
#include "cartpole_qlearning/simulation/perturbations.h"
#include "cartpole_qlearning/simulation/physics_engine.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <set>
#include <sstream>
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
  virtual bool get(const std::string& key, std::vector<std::string>& value) const = 0;
  // Every leaf key present below a section ("learning" -> "learning/gamma", "learning/epsilon/min", ...).
  virtual std::vector<std::string> keysUnder(const std::string& section) const = 0;
  // Where the parameters come from, for messages ("config/cartpole.yaml", "/cartpole").
  virtual std::string origin() const = 0;
  // The folder a relative path in these parameters is relative to (physics/model): a file's own
  // folder; empty: the working folder.
  virtual std::string folder() const
  {
    return "";
  }
  // A key as messages name it ("config/cartpole.yaml: learning/gamma", "parameter /cartpole/learning/gamma").
  virtual std::string describe(const std::string& key) const
  {
    return origin() + ": " + key;
  }
};

// Reads the keys of one section, remembers which keys it knows, and refuses the others, so
// that a misspelt key stops the run instead of being silently ignored.
class SectionReader
{
public:
  SectionReader(const ParameterSource& source, std::string section) : source_(source), section_(std::move(section)) {}

  template <typename T>
  void read(const std::string& name, T& value)
  {
    known_.insert(key(name));
    source_.get(key(name), value);
  }

  void read(const std::string& name, unsigned& value, std::int64_t min, std::int64_t max)
  {
    std::int64_t v = value;
    read(name, v);
    if (v < min || v > max)
      fail(name, std::to_string(v),
           "must be a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    value = static_cast<unsigned>(v);
  }

  // A finite number, > min (strict) or >= min.
  void readAtLeast(const std::string& name, double& value, double min, bool strict)
  {
    read(name, value);
    if (!(std::isfinite(value) && (strict ? value > min : value >= min)))
      fail(name, numberText(value), std::string("must be finite and ") + (strict ? "> " : ">= ") + numberText(min));
  }

  // A duration in seconds in [min, max] ((min, max] when strict): the message names the unit, so
  // that milliseconds typed as seconds (decision_period: 20) read as what they are.
  void readSeconds(const std::string& name, double& value, double min, double max, bool strict)
  {
    read(name, value);
    if (!(std::isfinite(value) && (strict ? value > min : value >= min) && value <= max))
      fail(name, numberText(value),
           std::string("must be in ") + (strict ? "(" : "[") + numberText(min) + ", " + numberText(max) +
               "] seconds (20 ms is 0.02)");
  }

  // One of the allowed strings.
  void readChoice(const std::string& name, std::string& value, const std::vector<std::string>& allowed)
  {
    read(name, value);
    if (std::find(allowed.begin(), allowed.end(), value) != allowed.end())
      return;
    std::string list;
    for (const std::string& a : allowed)
      list += (list.empty() ? "" : ", ") + a;
    fail(name, "'" + value + "'", "allowed: " + list);
  }

  void read(const std::string& name, std::uint64_t& value, std::int64_t min)
  {
    std::int64_t v = static_cast<std::int64_t>(value);
    read(name, v);
    if (v < min)
      fail(name, std::to_string(v), "must be a whole number >= " + std::to_string(min));
    value = static_cast<std::uint64_t>(v);
  }

  // A list of exactly kStateDimensions values.
  template <typename T>
  void readDimensions(const std::string& name, std::array<T, kStateDimensions>& values, bool whole)
  {
    std::vector<double> list;
    known_.insert(key(name));
    if (!source_.get(key(name), list))
      return;
    if (list.size() != kStateDimensions)
      fail(name, listText(list), "must list 4 values: x, x_dot, theta, theta_dot");
    for (std::size_t i = 0; i < kStateDimensions; ++i)
    {
      // Checked before the conversion: a value out of the type's range would be undefined.
      if (whole && (list[i] != std::floor(list[i]) || list[i] < 1 || list[i] > kMaxBinsPerDimension))
        fail(name, listText(list), "must be whole numbers in [1, " + std::to_string(kMaxBinsPerDimension) + "]");
      values[i] = static_cast<T>(list[i]);
    }
  }

  // A key read by other means (a value of a form the sources do not offer): not unknown.
  void know(const std::string& name)
  {
    known_.insert(key(name));
  }

  // Refuses a key under this section that no read() asked for.
  void refuseUnknown() const
  {
    for (const std::string& k : source_.keysUnder(section_))
    {
      if (known_.count(k) == 0)
        throw ConfigError(source_.origin() + ": unknown key " + k + " (known keys" +
                          (section_.empty() ? std::string() : " of " + section_) + ": " + knownText() + ")");
    }
  }

  // Turns a validate() message, which names the field relative to this section, into a ConfigError.
  void check(const std::string& error) const
  {
    if (!error.empty())
      throw ConfigError(source_.origin() + ": " + section_ + "/" + error);
  }

  [[noreturn]] void fail(const std::string& name, const std::string& value, const std::string& allowed) const
  {
    throw ConfigError(source_.describe(key(name)) + " = " + value + " is not allowed (" + allowed + ")");
  }

  // The key of a name in this section ("learning" + "gamma" -> "learning/gamma"; no section: the name).
  std::string key(const std::string& name) const
  {
    return section_.empty() ? name : section_ + "/" + name;
  }

  static std::string numberText(double value)
  {
    std::ostringstream out;
    out << value;
    return out.str();
  }

  static std::string listText(const std::vector<double>& list)
  {
    std::ostringstream out;
    out << "[";
    for (std::size_t i = 0; i < list.size(); ++i)
      out << (i ? ", " : "") << list[i];
    out << "]";
    return out.str();
  }

private:
  std::string knownText() const
  {
    std::string text;
    for (const std::string& k : known_)
      text += (text.empty() ? "" : ", ") + k.substr(section_.empty() ? 0 : section_.size() + 1);
    return text;
  }

  const ParameterSource& source_;
  std::string section_;
  std::set<std::string> known_;
};

// A YAML document as a parameter source. Throws ConfigError when the file cannot be read or parsed.
std::unique_ptr<ParameterSource> loadYamlParameters(const std::string& path);
// The folder a config file's relative paths are relative to: the file's own ("config/x.yaml" ->
// "config", "x.yaml" -> ".", "/x.yaml" -> "/"). The nodes use it on the launch's config_file.
std::string configFolder(const std::string& path);
// (folder: what folder() answers; loadYamlParameters gives the file's.)
std::unique_ptr<ParameterSource> parseYamlParameters(const std::string& text, const std::string& origin,
                                                     const std::string& folder = "");

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
