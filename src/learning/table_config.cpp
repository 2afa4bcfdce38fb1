#include "cartpole_qlearning/learning/table_config.h"

#include <utility>
#include <vector>

namespace cartpole_qlearning
{
namespace
{
template <typename Container>
std::string listText(const Container& values)
{
  std::string text;
  for (const auto value : values)
    text += (text.empty() ? "" : ", ") + exactText(static_cast<double>(value));
  return "[" + text + "]";
}

const char* flagText(bool value)
{
  return value ? "true" : "false";
}
}  // namespace

TableConfig tableConfig(const QTable& table, const std::string& table_path)
{
  TableConfig result;
  TrainingConfig& config = result.config;
  if (table.trained_with.empty())
    result.defaults_used = "the table " + table_path + " does not say which configuration trained it";
  else
  {
    try
    {
      config = readTrainingConfig(*parseYamlParameters(table.trained_with, table_path + ": trained_with"));
    }
    catch (const ConfigError& e)
    {
      // An early version 3 file said only the config's name: the defaults serve.
      config = TrainingConfig();
      result.defaults_used = "the table's trained_with is not a configuration (" + std::string(e.what()) + ")";
    }
  }
  if (!result.defaults_used.empty())
    result.defaults_used += ": the task (thresholds, reward) is the default one" +
                            std::string(table.tau > 0.0 ? "" : ", and so is the step (physics/tau 0.02 s)");
  // The header's features, actions and step, over the configuration's (the same by construction
  // when it carries one).
  const FeatureParams& features = table.features();
  AgentParams& agent = config.agent;
  agent.features = features.kind;
  agent.discretiser = features.discretiser;
  agent.tilings = features.tilings;
  agent.tiles = features.tiles;
  agent.second_tiles = features.second_tiles;
  agent.energy_tiles = features.energy_tiles;
  agent.pole_frequency = features.pole_frequency;
  agent.previous_action = features.previous_action;
  agent.actions = table.actions();
  if (table.tau > 0.0)
    config.physics.tau = table.tau;
  return result;
}

std::string tableContradiction(const TrainingConfig& config, const std::string& config_origin, const QTable& table,
                               const std::string& table_path)
{
  // (key, the config's value, the table's)
  std::vector<std::pair<std::string, std::pair<std::string, std::string>>> found;
  const auto differ = [&](const std::string& key, const std::string& in_config, const std::string& in_table) {
    if (in_config != in_table)
      found.push_back({key, {in_config, in_table}});
  };
  const FeatureParams wanted = config.agent.featureParams();
  const FeatureParams& has = table.features();
  differ("learning/features", toString(wanted.kind), toString(has.kind));
  if (wanted.kind == has.kind)
  {
    if (has.kind == FeatureKind::Bins)
      differ("learning/bins", listText(wanted.discretiser.bins), listText(has.discretiser.bins));
    else
    {
      differ("learning/tilings", std::to_string(wanted.tilings), std::to_string(has.tilings));
      differ("learning/tiles", listText(wanted.tiles), listText(has.tiles));
      if (wanted.hasSecondTiles() || has.hasSecondTiles())
        differ("learning/second_tiles", listText(wanted.second_tiles), listText(has.second_tiles));
      if (wanted.hasEnergyTiles() || has.hasEnergyTiles())
        differ("learning/energy_tiles", listText(wanted.energy_tiles), listText(has.energy_tiles));
      if (wanted.hasEnergyTiles() && has.hasEnergyTiles())
        differ("learning/pole_frequency", exactText(wanted.pole_frequency), exactText(has.pole_frequency));
    }
    // Tiles use the bounds of the dimensions they split only: what tiles them alike counts.
    const bool same_bounds =
        has.kind == FeatureKind::Bins ? wanted.discretiser == has.discretiser : wanted.tileCoder() == has.tileCoder();
    if (!same_bounds)
    {
      differ("learning/lower_bounds", listText(wanted.discretiser.lower), listText(has.discretiser.lower));
      differ("learning/upper_bounds", listText(wanted.discretiser.upper), listText(has.discretiser.upper));
    }
  }
  differ("learning/previous_action", flagText(wanted.previous_action), flagText(has.previous_action));
  differ("learning/actions", listText(config.agent.actions), listText(table.actions()));
  if (table.tau > 0.0)
    differ("physics/tau", exactText(config.physics.tau), exactText(table.tau));
  std::string text;
  for (const auto& [key, values] : found)
    text += (text.empty() ? "" : "; ") + key + " is " + values.first + " in " + config_origin + " but " +
            values.second + " in the table " + table_path;
  return text;
}

}  // namespace cartpole_qlearning
