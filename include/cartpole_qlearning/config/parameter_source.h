// Where settings come from, whatever holds them: a YAML file (io/yaml_parameters.h), the ROS
// parameter server (src/ros/parameter_source.h), YAML text in a test. The readers ask a source by
// slash-separated keys, so a key means the same thing, and is checked the same way, wherever it is set.
#pragma once

#include "cartpole_qlearning/config/config_error.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// Keys are slash-separated paths such as "learning/gamma". Each get() returns false when the key is
// absent and throws ConfigError when it is present with a value of the wrong type.
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
  // A list of maps (a suite's cases): each entry a source whose keys are the entry's own and whose
  // origin is "ORIGIN: KEY[i]", or nullptr for an entry that is not a map. False when the key is
  // absent; throws ConfigError when it is not a list. (Sources without such lists refuse the key.)
  virtual bool getEntries(const std::string& key, std::vector<std::unique_ptr<ParameterSource>>& entries) const
  {
    (void)entries;
    throw ConfigError(describe(key) + ": a list of maps cannot be read from here");
  }
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

}  // namespace cartpole_qlearning
