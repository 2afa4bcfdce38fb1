// What the controller's and the sim's readers share (private to src/node_settings/).
#pragma once

#include "cartpole_qlearning/application/suite_file.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/protocol/robot_interface.h"

#include <optional>
#include <string>
#include <utility>

namespace cartpole_qlearning
{
// A value of any form as messages show it (for a key whose forms are all wrong).
std::string anyValueText(const ParameterSource& source, const std::string& key);

// ~suite and ~suite_case (the sim and the controller alike): the case, loaded with the suite's
// episodes and seed, or nullopt when no case is named. base: the physics the cases vary.
std::optional<std::pair<RobustnessSuite, SuiteCase>> readSuiteCase(SectionReader& priv, const TrainingConfig& base);

// A MuJoCo model's joints are the robot's by default (the sim publishes them; ~cart_joint and
// ~pole_joint still win): one config names them for the sim and the controller alike.
void useModelJoints(const EngineParams& engine, RobotInterfaceParams& robot);

}  // namespace cartpole_qlearning
