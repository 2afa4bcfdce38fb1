#include "cartpole_qlearning/learning/policy_grid.h"

#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/table_config.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
std::string number(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// A point i of n evenly spread over [lower, upper], the ends exact.
double spread(std::size_t i, std::size_t n, double lower, double upper)
{
  if (i + 1 == n)
    return upper;
  return lower + (upper - lower) * static_cast<double>(i) / static_cast<double>(n - 1);
}
}  // namespace

std::string PolicyGridParams::validate(std::size_t actions) const
{
  std::ostringstream out;
  if (x_dimension >= kStateDimensions || y_dimension >= kStateDimensions || x_dimension == y_dimension)
    return "the two axes must be two different state dimensions";
  if (points < 2 || points > kMaxPolicyGridPoints)
  {
    out << "points = " << points << " is not allowed (must be in [2, " << kMaxPolicyGridPoints << "])";
    return out.str();
  }
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (d != x_dimension && d != y_dimension && !std::isfinite(slice[d]))
    {
      out << "the slice's " << stateDimensionName(d) << " = " << slice[d] << " is not allowed (must be finite)";
      return out.str();
    }
  }
  if (previous > actions)
  {
    out << "previous = " << previous << " is not allowed (0 for none, else 1 + an action index: at most " << actions
        << ")";
    return out.str();
  }
  return "";
}

PolicyGrid policyGrid(const QTable& table, const PolicyGridParams& params)
{
  const std::string error = params.validate(table.actionCount());
  if (!error.empty())
    throw std::invalid_argument(error);
  // The controller's own agent on this table: its features find the rows, its greedy choice the
  // action, so ties and tiles' sums are broken and added exactly as when it acts.
  const FeatureParams& features = table.features();
  AgentParams agent_params;
  agent_params.features = features.kind;
  agent_params.discretiser = features.discretiser;
  agent_params.tilings = features.tilings;
  agent_params.tiles = features.tiles;
  agent_params.second_tiles = features.second_tiles;
  agent_params.energy_tiles = features.energy_tiles;
  agent_params.pole_frequency = features.pole_frequency;
  agent_params.previous_action = features.previous_action;
  agent_params.actions = table.actions();
  // What maps states onto rows beyond the file's header (warp, mirror) is in the configuration the
  // table carries (the defaults when it carries none).
  if (!table.trained_with.empty())
  {
    const AgentParams carried = tableConfig(table, "").config.agent;
    agent_params.warp = carried.warp;
    agent_params.mirror = carried.mirror;
  }
  QLearningAgent agent(agent_params, 0);
  const std::string mismatch = agent.replaceTable(table);
  if (!mismatch.empty())  // cannot happen: the agent was made from the table's own shape
    throw std::invalid_argument(mismatch);

  PolicyGrid grid;
  grid.params = params;
  const DiscretiserParams& bounds = features.discretiser;
  grid.x_lower = bounds.lower[params.x_dimension];
  grid.x_upper = bounds.upper[params.x_dimension];
  grid.y_lower = bounds.lower[params.y_dimension];
  grid.y_upper = bounds.upper[params.y_dimension];
  for (const std::size_t d : {params.x_dimension, params.y_dimension})
    if (!(std::isfinite(bounds.lower[d]) && std::isfinite(bounds.upper[d]) && bounds.lower[d] < bounds.upper[d]))
      throw std::invalid_argument(std::string("the table's bounds of ") + stateDimensionName(d) +
                                  " are not a range to plot over");

  const std::size_t n = params.points;
  grid.points.reserve(n * n);
  CartPoleState state = params.slice;
  ActiveRows active;
  for (std::size_t j = 0; j < n; ++j)
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      PolicyPoint point;
      point.x = spread(i, n, grid.x_lower, grid.x_upper);
      point.y = spread(j, n, grid.y_lower, grid.y_upper);
      state[params.x_dimension] = point.x;
      state[params.y_dimension] = point.y;
      agent.activeRows(state, active, params.previous);
      point.action = agent.greedyAction(active);
      point.value = agent.value(active, point.action);
      point.tie = true;
      for (std::size_t a = 0; a < table.actionCount() && point.tie; ++a)
        point.tie = agent.value(active, a) == point.value;
      grid.points.push_back(point);
    }
  }
  return grid;
}

std::string policyGridCsv(const PolicyGrid& grid, const QTable& table)
{
  const PolicyGridParams& p = grid.params;
  const FeatureParams& features = table.features();
  std::ostringstream out;
  out << "# policy: the greedy action and max_a Q of a cartpole_qlearning Q-table\n";
  out << "# features: " << toString(features.kind);
  if (features.kind == FeatureKind::Tiles)
  {
    out << " (" << features.tilings << " tilings of " << features.tiles[0] << "x" << features.tiles[1] << "x"
        << features.tiles[2] << "x" << features.tiles[3] << " tiles";
    if (features.hasSecondTiles())
      out << ", and " << features.tilings << " of " << features.second_tiles[0] << "x" << features.second_tiles[1]
          << "x" << features.second_tiles[2] << "x" << features.second_tiles[3];
    if (features.hasEnergyTiles())
      out << ", and " << features.tilings << " of " << features.energy_tiles[0] << "x" << features.energy_tiles[1]
          << "x" << features.energy_tiles[2] << "x" << features.energy_tiles[3] << " over the swing";
    out << ")";
  }
  else
    out << " (" << features.discretiser.bins[0] << "x" << features.discretiser.bins[1] << "x"
        << features.discretiser.bins[2] << "x" << features.discretiser.bins[3] << " bins)";
  out << "\n# episodes: " << table.episodes << "\n# actions:";
  for (const double effort : table.actions())
    out << " " << number(effort);
  out << "\n# slice:";
  for (std::size_t d = 0; d < kStateDimensions; ++d)
    if (d != p.x_dimension && d != p.y_dimension)
      out << " " << stateDimensionName(d) << "=" << number(p.slice[d]);
  if (features.previous_action)
    out << " previous=" << (p.previous == 0 ? std::string("none") : std::to_string(p.previous - 1));
  out << "\n# bounds: " << stateDimensionName(p.x_dimension) << " " << number(grid.x_lower) << " "
      << number(grid.x_upper) << ", " << stateDimensionName(p.y_dimension) << " " << number(grid.y_lower) << " "
      << number(grid.y_upper) << "\n";
  out << stateDimensionName(p.x_dimension) << "," << stateDimensionName(p.y_dimension) << ",action,effort,value,tie\n";
  for (const PolicyPoint& point : grid.points)
    out << number(point.x) << "," << number(point.y) << "," << point.action << ","
        << number(table.actions()[point.action]) << "," << number(point.value) << "," << (point.tie ? 1 : 0) << "\n";
  return out.str();
}

}  // namespace cartpole_qlearning
