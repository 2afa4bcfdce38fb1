// The robot's side of the nodes' parameters, read alike wherever they are: its pose (joints,
// offsets, signs: the controller reads a robot's, the sim poses as one) and the command it takes
// (the controller and the command watchdog).
#pragma once

#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/protocol/robot_interface.h"

namespace cartpole_qlearning
{
// The pose: ~cart_joint and ~pole_joint (not empty, not the same), ~cart_zero and ~pole_upright
// (finite), ~cart_sign, ~pole_angle_sign and ~effort_sign (1 or -1). Throws ConfigError naming a
// bad one.
void readRobotPose(SectionReader& priv, RobotInterfaceParams& robot);

// The command a robot takes: ~command_type, ~command_joint (robot.cart_joint unless given),
// ~command_index and ~command_size; read alike by the controller and the command watchdog.
// Throws ConfigError naming a bad one.
void readRobotCommand(SectionReader& priv, RobotInterfaceParams& robot);

}  // namespace cartpole_qlearning
