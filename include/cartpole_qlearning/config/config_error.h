// The one error every settings reader throws: a config file, a suite file, the parameter server.
#pragma once

#include <stdexcept>

namespace cartpole_qlearning
{
// A bad key or value. The message names the key, the value and what is allowed.
class ConfigError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

}  // namespace cartpole_qlearning
