#include "cartpole_qlearning/application/suite_file.h"

#include "cartpole_qlearning/simulation/engine_registry.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
std::uint64_t wholeNumber(const YAML::Node& node, const std::string& where, std::uint64_t min, std::uint64_t max)
{
  long long value = 0;
  try
  {
    value = node.as<long long>();
  }
  catch (const YAML::Exception&)
  {
    throw ConfigError(where + " = '" + YAML::Dump(node) + "' is not allowed (must be a whole number)");
  }
  if (value < static_cast<long long>(min) || static_cast<unsigned long long>(value) > max)
    throw ConfigError(where + " = " + std::to_string(value) + " is not allowed (must be in [" + std::to_string(min) +
                      ", " + std::to_string(max) + "])");
  return static_cast<std::uint64_t>(value);
}

double boundValue(const YAML::Node& node, const std::string& where)
{
  double value = -1.0;
  try
  {
    value = node.as<double>();
  }
  catch (const YAML::Exception&)
  {
  }
  if (!(std::isfinite(value) && value >= 0.0))
    throw ConfigError(where + " = '" + YAML::Dump(node) + "' is not allowed (must be a finite number >= 0)");
  return value;
}
}  // namespace

RobustnessSuite parseRobustnessSuite(const std::string& yaml, const std::string& origin, const TrainingConfig& base)
{
  RobustnessSuite suite;
  suite.origin = origin;
  YAML::Node root;
  try
  {
    root = YAML::Load(yaml);
  }
  catch (const YAML::Exception& e)
  {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap())
    throw ConfigError(origin + ": must be a map with the keys episodes, seed and cases");
  for (const auto& entry : root)
  {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : YAML::Dump(entry.first);
    if (key == "episodes")
      suite.episodes = wholeNumber(entry.second, origin + ": episodes", 1, 1000000);
    else if (key == "seed")
      suite.seed = wholeNumber(entry.second, origin + ": seed", 0, std::numeric_limits<long long>::max());
    else if (key == "max_episode_steps")
      suite.max_episode_steps = static_cast<unsigned>(
          wholeNumber(entry.second, origin + ": max_episode_steps", 1, std::numeric_limits<int>::max()));
    else if (key == "start_state_bound")
      suite.start_state_bound = boundValue(entry.second, origin + ": start_state_bound");
    else if (key != "cases")
      throw ConfigError(origin + ": unknown key " + key +
                        " (known keys: episodes, seed, max_episode_steps, start_state_bound, cases)");
  }
  const YAML::Node cases = root["cases"];
  if (!cases || !cases.IsSequence() || cases.size() == 0)
    throw ConfigError(origin + ": cases must be a list of cases, each with a name");
  std::set<std::string> names;
  for (std::size_t i = 0; i < cases.size(); ++i)
  {
    const YAML::Node node = cases[i];
    const std::string where = origin + ": cases[" + std::to_string(i) + "]";
    if (!node.IsMap() || !node["name"] || !node["name"].IsScalar() || node["name"].Scalar().empty())
      throw ConfigError(where + " must be a map with a name");
    SuiteCase c;
    c.name = node["name"].Scalar();
    if (!names.insert(c.name).second)
      throw ConfigError(where + ": the name " + c.name + " is used twice");
    c.physics = base.physics;
    c.engine = base.engine;
    c.start_state_bound = suite.start_state_bound;
    YAML::Node sections(YAML::NodeType::Map);
    for (const auto& entry : node)
    {
      const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : YAML::Dump(entry.first);
      if (key == "pass")
        c.pass = wholeNumber(entry.second, origin + ": case " + c.name + ": pass", 0, suite.episodes);
      else if (key == "physics" || key == "perturbations")
        sections[key] = entry.second;
      else if (key != "name")
        throw ConfigError(origin + ": case " + c.name + ": unknown key " + key +
                          " (known keys: name, pass, physics, perturbations)");
    }
    // The case's sections, read by the configuration's own readers: the same keys, checks and messages.
    // (A case's model is relative to the suite file's folder.)
    const auto source = parseYamlParameters(YAML::Dump(sections), origin + ": case " + c.name, configFolder(origin));
    readPhysics(*source, c.physics, c.start_state_bound, c.engine);
    c.perturbations = readPerturbations(*source);
    checkPerturbationsFitEngine(*source, c.engine, c.perturbations);
    suite.cases.push_back(c);
  }
  return suite;
}

RobustnessSuite loadRobustnessSuite(const std::string& path, const TrainingConfig& base)
{
  std::ifstream in(path);
  if (!in)
    throw ConfigError(path + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return parseRobustnessSuite(text.str(), path, base);
}

bool episodesRunInAnyOrder(const SuiteCase& suite_case)
{
  return engineOf(suite_case.engine).episodes_independent && !suite_case.perturbations.drawsWhileStepping();
}
}  // namespace cartpole_qlearning
