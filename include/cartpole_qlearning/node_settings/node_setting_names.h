// The settings the core's messages point at (common/setting_names.h), named as the nodes' users
// set them: private parameters, with the launch argument where a launch file sets it.
#pragma once

#include "cartpole_qlearning/common/setting_names.h"

#include <string>

namespace cartpole_qlearning
{
// "~load_on_start", "~save_q_table", "~state_topic (robot.launch joint_states:=)", ...
SettingNames nodeSettingNames();

// The private parameter that holds a setting, without "~" (as ros::NodeHandle names it), for a
// refusal of its value; "" for a setting that is not a parameter.
std::string nodeParameterName(Setting setting);

}  // namespace cartpole_qlearning
