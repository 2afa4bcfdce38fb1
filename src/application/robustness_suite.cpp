#include "cartpole_qlearning/application/robustness_suite.h"

#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
    const auto source = parseYamlParameters(YAML::Dump(sections), origin + ": case " + c.name);
    readPhysics(*source, c.physics, c.start_state_bound);
    c.perturbations = readPerturbations(*source);
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

CaseResult evaluateCase(const QTable& table, const TrainingConfig& config, const SuiteCase& suite_case,
                        std::uint64_t episodes, std::uint64_t seed)
{
  TrainingSession session(config.task, config.agent, seed, false);
  const std::string mismatch = session.replaceTable(table);
  if (!mismatch.empty())
    throw ConfigError("the table does not fit the configuration: " + mismatch);
  CartPoleSimulation simulation(suite_case.physics, suite_case.start_state_bound, seed, suite_case.perturbations);
  CaseResult result;
  result.name = suite_case.name;
  result.pass = suite_case.pass;
  double returns = 0.0;
  for (std::uint64_t e = 0; e < episodes; ++e)
  {
    simulation.resetRandom();
    double effort = session.beginEpisode(simulation.observation());
    for (;;)
    {
      simulation.step(effort);
      const Decision decision = session.observe(simulation.observation());
      if (decision.episode_over)
        break;
      effort = decision.effort;
    }
    const EpisodeSummary& s = session.lastEpisode();
    result.balanced += s.truncated && !s.terminated;
    returns += s.episode_return;
  }
  result.episodes = episodes;
  result.mean_return = episodes > 0 ? returns / static_cast<double>(episodes) : 0.0;
  return result;
}

SuiteResult evaluateSuite(const QTable& table, const TrainingConfig& config, const RobustnessSuite& suite)
{
  TrainingConfig judged = config;
  judged.task.max_episode_steps = suite.max_episode_steps;
  SuiteResult result;
  for (const SuiteCase& c : suite.cases)
    result.cases.push_back(evaluateCase(table, judged, c, suite.episodes, suite.seed));
  return result;
}

double shownReturn(double value, int decimals)
{
  const double scale = std::pow(10.0, decimals);
  // + 0.0 turns -0.0 into 0.0 (IEEE 754 rounding to nearest).
  return std::round(value * scale) / scale + 0.0;
}

bool SuiteResult::passed() const
{
  return std::all_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.passed(); });
}

std::uint64_t SuiteResult::worstBalanced() const
{
  std::uint64_t worst = std::numeric_limits<std::uint64_t>::max();
  for (const CaseResult& c : cases)
    worst = std::min(worst, c.balanced);
  return cases.empty() ? 0 : worst;
}

std::string SuiteResult::summary() const
{
  std::string text;
  for (const CaseResult& c : cases)
    text += (text.empty() ? "" : ", ") + c.name + " " + std::to_string(c.balanced) + "/" + std::to_string(c.episodes);
  return text + ": " + (passed() ? "PASSED" : "FAILED");
}

std::string SuiteResult::table() const
{
  std::size_t width = 4;
  for (const CaseResult& c : cases)
    width = std::max(width, c.name.size());
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-*s  %8s  %6s  %11s  %s\n", static_cast<int>(width), "case", "balanced", "needed",
                "mean return", "verdict");
  out << line;
  for (const CaseResult& c : cases)
  {
    const std::string balanced = std::to_string(c.balanced) + "/" + std::to_string(c.episodes);
    std::snprintf(line, sizeof line, "%-*s  %8s  %6llu  %11.1f  %s\n", static_cast<int>(width), c.name.c_str(),
                  balanced.c_str(), static_cast<unsigned long long>(c.pass), shownReturn(c.mean_return, 1),
                  c.passed() ? "pass" : "FAIL");
    out << line;
  }
  out << summary();
  return out.str();
}

}  // namespace cartpole_qlearning
