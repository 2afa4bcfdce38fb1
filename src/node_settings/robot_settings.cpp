#include "cartpole_qlearning/node_settings/robot_settings.h"

#include "settings_parts.h"

#include "cartpole_qlearning/simulation/engine_registry.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace cartpole_qlearning
{
namespace
{
void readSign(SectionReader& priv, const std::string& name, double& sign)
{
  priv.read(name, sign);
  if (sign != 1.0 && sign != -1.0)
    priv.fail(name, SectionReader::numberText(sign), "must be 1 or -1");
}

void readFinite(SectionReader& priv, const std::string& name, double& value)
{
  priv.read(name, value);
  if (!std::isfinite(value))
    priv.fail(name, SectionReader::numberText(value), "must be finite");
}

}  // namespace

std::string anyValueText(const ParameterSource& source, const std::string& key)
{
  const auto quoted = [](const std::string& text) { return "'" + text + "'"; };
  try
  {
    std::string text;
    if (source.get(key, text))
      return quoted(text);
  }
  catch (const ConfigError&)
  {
  }
  try
  {
    double number = 0.0;
    if (source.get(key, number))
      return SectionReader::numberText(number);
  }
  catch (const ConfigError&)
  {
  }
  try
  {
    bool flag = false;
    if (source.get(key, flag))
      return flag ? "true" : "false";
  }
  catch (const ConfigError&)
  {
  }
  try
  {
    std::vector<double> numbers;
    if (source.get(key, numbers))
      return SectionReader::listText(numbers);
  }
  catch (const ConfigError&)
  {
  }
  const std::vector<std::string> keys = source.keysUnder(key);
  return keys.size() == 1 && keys.front() == key ? "a list of mixed values" : "a map";
}

std::optional<std::pair<RobustnessSuite, SuiteCase>> readSuiteCase(SectionReader& priv, const TrainingConfig& base)
{
  std::string path;
  std::string name;
  priv.read("suite", path);
  priv.read("suite_case", name);
  if (name.empty())
    return std::nullopt;
  if (path.empty())
    priv.fail("suite_case", "'" + name + "'", "needs ~suite, the suite file that holds the case");
  const RobustnessSuite suite = loadRobustnessSuite(path, base);
  std::string names;
  for (const SuiteCase& c : suite.cases)
  {
    if (c.name == name)
      return std::make_pair(suite, c);
    names += (names.empty() ? "" : ", ") + c.name;
  }
  priv.fail("suite_case", "'" + name + "'", "the cases of " + path + ": " + names);
}

void useModelJoints(const EngineParams& engine, RobotInterfaceParams& robot)
{
  if (!engineOf(engine).names_joints)
    return;
  robot.cart_joint = engine.cart_joint;
  robot.pole_joint = engine.pole_joint;
}

void readRobotPose(SectionReader& priv, RobotInterfaceParams& robot)
{
  for (const auto& [name, joint] :
       {std::pair<const char*, std::string*>{"cart_joint", &robot.cart_joint}, {"pole_joint", &robot.pole_joint}})
  {
    priv.read(name, *joint);
    if (joint->empty())
      priv.fail(name, "''", "must not be empty");
  }
  if (robot.cart_joint == robot.pole_joint)
    priv.fail("pole_joint", "'" + robot.pole_joint + "'", "must differ from ~cart_joint");
  readFinite(priv, "cart_zero", robot.cart_zero);
  readFinite(priv, "pole_upright", robot.pole_upright);
  readSign(priv, "cart_sign", robot.cart_sign);
  readSign(priv, "pole_angle_sign", robot.pole_angle_sign);
  readSign(priv, "effort_sign", robot.effort_sign);
}

void readRobotCommand(SectionReader& priv, RobotInterfaceParams& robot)
{
  std::string type = "joint_state";
  priv.readChoice("command_type", type, {"joint_state", "float64", "float64_array"});
  robot.command_type = type == "float64"         ? CommandType::Float64
                       : type == "float64_array" ? CommandType::Float64Array
                                                 : CommandType::JointState;
  robot.command_joint = robot.cart_joint;
  priv.read("command_joint", robot.command_joint);
  if (robot.command_joint.empty())
    priv.fail("command_joint", "''", "must name the cart's joint as the robot takes commands for it");
  std::uint64_t index = 0;
  std::uint64_t size = 1;
  priv.read("command_index", index, 0);
  priv.read("command_size", size, 1);
  if (index >= size)
    priv.fail("command_index", std::to_string(index), "must be < ~command_size = " + std::to_string(size));
  robot.command_index = static_cast<std::size_t>(index);
  robot.command_size = static_cast<std::size_t>(size);
}

}  // namespace cartpole_qlearning
