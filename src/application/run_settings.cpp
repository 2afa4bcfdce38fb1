#include "cartpole_qlearning/application/run_settings.h"

namespace cartpole_qlearning
{
std::vector<std::string> robotNamespaces(std::size_t count)
{
  if (count == 1)
    return {""};
  std::vector<std::string> names;
  for (std::size_t i = 0; i < count; ++i)
    names.push_back("robot_" + std::to_string(i));
  return names;
}

}  // namespace cartpole_qlearning
