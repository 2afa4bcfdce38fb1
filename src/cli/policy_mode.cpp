#include "headless_modes.h"

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/policy_grid.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/node_settings/table_folder.h"

#include <cstdio>
#include <iostream>
#include <stdexcept>

namespace cartpole_qlearning
{
// --policy TABLE: the table's greedy policy over a grid, as CSV on stdout. Exit 2 on a table that
// cannot be read or a bad grid, the message naming what.
int policyMode(const HeadlessOptions& options)
{
  const std::string& table_path = options.policy_path;
  const std::string& axes = options.axes;
  const std::string& at = options.policy_at;
  const std::string& previous = options.previous;
  PolicyGridParams params;
  params.points = options.grid_points;
  try
  {
    const std::size_t comma = axes.find(',');
    if (comma == std::string::npos)
      throw std::invalid_argument("give two dimensions, e.g. theta,theta_dot");
    params.x_dimension = stateDimension(axes.substr(0, comma));
    params.y_dimension = stateDimension(axes.substr(comma + 1));
    if (params.x_dimension == params.y_dimension)
      throw std::invalid_argument("the two axes must be two different dimensions");
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "train_headless: --axes " << axes << " is not allowed (" << e.what() << ")\n";
    return 2;
  }
  std::string rest = at;
  while (!rest.empty())
  {
    const std::string item = rest.substr(0, rest.find(','));
    rest = item.size() < rest.size() ? rest.substr(item.size() + 1) : std::string();
    const std::size_t equals = item.find('=');
    try
    {
      if (equals == std::string::npos)
        throw std::invalid_argument("give NAME=VALUE, e.g. x=0.5");
      const std::size_t d = stateDimension(item.substr(0, equals));
      if (d == params.x_dimension || d == params.y_dimension)
        throw std::invalid_argument(item.substr(0, equals) + " is an axis");
      std::size_t used = 0;
      const std::string value = item.substr(equals + 1);
      params.slice[d] = std::stod(value, &used);
      if (used != value.size())
        throw std::invalid_argument("not a number: " + value);
    }
    catch (const std::logic_error& e)  // invalid_argument, out_of_range
    {
      std::cerr << "train_headless: --at " << at << " is not allowed (" << e.what() << ")\n";
      return 2;
    }
  }
  QTable table;
  try
  {
    table = loadTable(defaultTableDirectory(options.name_space), table_path);
  }
  catch (const FileError& e)
  {
    std::cerr << "train_headless: --policy " << table_path << ": " << e.what() << "\n";
    return 2;
  }
  if (previous != "none")
  {
    std::uint64_t index = 0;
    if (!parseCount(previous, index) || index >= table.actionCount())
    {
      std::cerr << "train_headless: --previous " << previous << " is not allowed (none, or an action index below "
                << table.actionCount() << ")\n";
      return 2;
    }
    params.previous = index + 1;
  }
  try
  {
    const PolicyGrid grid = policyGrid(table, params);
    std::fputs(policyGridCsv(grid, table).c_str(), stdout);
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "train_headless: --policy " << table_path << ": " << e.what() << "\n";
    return 2;
  }
  return 0;
}

}  // namespace cartpole_qlearning
