// The engines' registry (engine_registry.h): what the config, the sim and the suite ask of an engine.
#include "cartpole_qlearning/simulation/engine_registry.h"

#include <gtest/gtest.h>

#include <map>
#include <stdexcept>
#include <string>

using namespace cartpole_qlearning;

namespace
{
TEST(EngineRegistry, KnowsTheEnginesByNameTheDefaultFirst)
{
  ASSERT_GE(engineDescriptions().size(), 2u);
  EXPECT_EQ(EngineParams().name, engineDescriptions().front().name) << "the default engine is the first listed";
  EXPECT_EQ("equations", engineNamed("equations").name);
  EXPECT_EQ("mujoco", engineNamed("mujoco").name);
  try
  {
    engineNamed("bullet");
    ADD_FAILURE() << "an unknown engine was found";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_EQ(std::string("unknown engine 'bullet' (allowed: equations, mujoco)"), e.what());
  }
}

TEST(EngineRegistry, EachKeyBelongsToOneEngineAndSetsOneValue)
{
  std::map<std::string, std::string> owner;
  for (const EngineDescription& engine : engineDescriptions())
  {
    EXPECT_TRUE(engine.describe && engine.make) << engine.name;
    for (const EngineKey& key : engine.keys)
    {
      EXPECT_TRUE(owner.emplace(key.name, engine.name).second)
          << key.name << " is " << owner[key.name] << "'s and " << engine.name << "'s";
      EXPECT_EQ(1, (key.number != nullptr) + (key.choice != nullptr) + (key.text != nullptr)) << key.name;
      EXPECT_TRUE(key.file.empty() || key.text != nullptr) << key.name << ": a file is named by a text";
      for (const char* shared : {"engine", "force_mag", "tau", "start_state_bound"})
        EXPECT_NE(shared, key.name) << "every engine takes " << shared;
    }
  }
}

TEST(EngineRegistry, MakesTheEquationsAndSaysWhatTheyAllow)
{
  CartPoleParams physics;
  physics.integrator = Integrator::Rk4;
  // (A named EngineParams: GCC 14 warns of a reference returned for a temporary argument.)
  const EngineParams defaults;
  const EngineDescription& equations = engineOf(defaults);
  const auto engine = equations.make(physics, defaults);
  ASSERT_NE(nullptr, dynamic_cast<EquationsEngine*>(engine.get()));
  EXPECT_EQ(physics.tau, engine->tau());
  EXPECT_EQ("integrator rk4", equations.describe(physics, EngineParams()));
  EXPECT_TRUE(equations.scales_half_length && equations.episodes_independent && equations.makes_in_parallel);
  EXPECT_FALSE(equations.names_joints) << "the sim publishes the URDF's joints";
  EngineParams model;
  model.name = "mujoco";
  model.model = "/models/cartpole.xml";
  EXPECT_TRUE(engineOf(model).names_joints);
  EXPECT_EQ("MuJoCo model /models/cartpole.xml", engineOf(model).describe(physics, model));
}

}  // namespace
