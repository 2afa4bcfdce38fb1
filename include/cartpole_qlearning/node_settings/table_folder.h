// Where the nodes and train_headless keep tables by default: a ROS convention (ROS_HOME), kept out
// of the core, which takes the folder as a value (RunSettings::q_table_dir).
#pragma once

#include <string>

namespace cartpole_qlearning
{
// Where a controller in this ROS namespace keeps its tables unless told otherwise, and where
// train_headless saves a relative --save path: $ROS_HOME/cartpole_qlearning<namespace>
// ($ROS_HOME defaults to ~/.ros), e.g. ~/.ros/cartpole_qlearning/cartpole for "/cartpole".
std::string defaultTableDirectory(const std::string& name_space);

}  // namespace cartpole_qlearning
