#include "cartpole_qlearning/node_settings/table_folder.h"

#include <cstdlib>

namespace cartpole_qlearning
{
std::string defaultTableDirectory(const std::string& name_space)
{
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  const std::string base = ros_home != nullptr && *ros_home != '\0'
                               ? std::string(ros_home) + "/cartpole_qlearning"
                               : std::string(home != nullptr ? home : ".") + "/.ros/cartpole_qlearning";
  if (name_space.empty() || name_space == "/")
    return base;
  return base + (name_space.front() == '/' ? "" : "/") + name_space;
}

}  // namespace cartpole_qlearning
