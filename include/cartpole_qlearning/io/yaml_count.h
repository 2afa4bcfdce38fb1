// Whole numbers >= 0 read from YAML alike on every yaml-cpp. Before 0.7 (0.6.3 on Debian 11, 0.6.2
// on Noetic's Ubuntu 20.04) yaml-cpp reads "-1" into an unsigned type through a stream, which
// gives that type's largest value; 0.7 refuses it. A table file or run record saying "steps: -1"
// is refused on both.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>

namespace cartpole_qlearning
{
// node.as<std::uint64_t>(), refusing a scalar written with a minus sign as yaml-cpp 0.7 does
// (YAML::TypedBadConversion).
inline std::uint64_t yamlCount(const YAML::Node& node)
{
  if (node.IsScalar() && !node.Scalar().empty() && node.Scalar().front() == '-')
    throw YAML::TypedBadConversion<std::uint64_t>(node.Mark());
  return node.as<std::uint64_t>();
}

}  // namespace cartpole_qlearning
