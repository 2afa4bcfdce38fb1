// The ROS parameter server as a ParameterSource, so the nodes read the physics, task and
// learning keys with the same reader, defaults and checks as train_headless reads the YAML.
#pragma once

#include "cartpole_qlearning/node_settings/controller_settings.h"
#include "cartpole_qlearning/learning/training_config.h"

#include <ros/node_handle.h>

namespace cartpole_qlearning
{
class RosParameterSource : public ParameterSource
{
public:
  // Keys are resolved relative to the node handle's namespace ("physics/tau" -> /cartpole/physics/tau).
  explicit RosParameterSource(const ros::NodeHandle& nh) : nh_(nh) {}

  bool get(const std::string& key, double& value) const override;
  bool get(const std::string& key, std::int64_t& value) const override;
  bool get(const std::string& key, bool& value) const override;
  bool get(const std::string& key, std::string& value) const override;
  bool get(const std::string& key, std::vector<double>& value) const override;
  bool get(const std::string& key, std::vector<std::string>& value) const override;
  std::vector<std::string> keysUnder(const std::string& section) const override;
  std::string origin() const override;
  std::string describe(const std::string& key) const override;
  // The folder of the config file the launch loaded here, which it names in config_file beside
  // the config's sections (a relative physics/model is relative to it, as train_headless
  // --config has it); "" when none is named.
  std::string folder() const override;

private:
  ros::NodeHandle nh_;
};

// Throws ConfigError "parameter /ns/node/name = value is not allowed (allowed)".
[[noreturn]] void refuseParameter(const ros::NodeHandle& nh, const std::string& name, const std::string& value,
                                  const std::string& allowed);

// The controller's settings from the parameter server: the learner's namespace (nh) and the
// node's private one (pnh), with the live tuning's keys and the package's suite folder known.
// Throws ConfigError naming a bad parameter.
ControllerSettings readControllerParameters(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                            bool shutdown_by_default);

}  // namespace cartpole_qlearning
