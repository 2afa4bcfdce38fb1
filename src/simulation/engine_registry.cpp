#include "cartpole_qlearning/simulation/engine_registry.h"

#include <stdexcept>

namespace cartpole_qlearning
{
// Each engine's description, in its own files.
EngineDescription equationsEngineDescription();  // physics_engine.cpp
EngineDescription mujocoEngineDescription();     // mujoco_loader.cpp

const std::vector<EngineDescription>& engineDescriptions()
{
  // One line per engine; the first is the default (EngineParams::name).
  static const std::vector<EngineDescription> engines = {
      equationsEngineDescription(),
      mujocoEngineDescription(),
  };
  return engines;
}

const EngineDescription& engineNamed(const std::string& name)
{
  std::string allowed;
  for (const EngineDescription& engine : engineDescriptions())
  {
    if (engine.name == name)
      return engine;
    allowed += (allowed.empty() ? "" : ", ") + engine.name;
  }
  throw std::invalid_argument("unknown engine '" + name + "' (allowed: " + allowed + ")");
}

}  // namespace cartpole_qlearning
