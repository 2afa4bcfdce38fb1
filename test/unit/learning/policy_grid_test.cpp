// The policy picture's numbers: each grid point's action and value are what the controller's
// agent chooses and expects in that state, for bins and tiles alike.
#include "cartpole_qlearning/learning/policy_grid.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/learning/training_config.h"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>

using namespace cartpole_qlearning;

namespace
{
// An agent with varied weights: Q(row, a) from a formula, so that every state has its own values.
QLearningAgent trainedLike(const AgentParams& params)
{
  QLearningAgent agent(params, 0);
  std::vector<double> values(agent.table().values().size());
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<double>((i * 7919) % 101) - 50.0;
  agent.table().setValues(values);
  return agent;
}

AgentParams tiles()
{
  AgentParams params;
  params.features = FeatureKind::Tiles;
  params.tilings = 4;
  params.tiles = {{1, 1, 8, 12}};
  return params;
}
}  // namespace

TEST(PolicyGridTest, EveryPointIsTheAgentsGreedyActionAndItsValue)
{
  for (const AgentParams& params : {AgentParams(), tiles()})
  {
    const QLearningAgent agent = trainedLike(params);
    PolicyGridParams grid_params;
    grid_params.points = 23;
    grid_params.slice = CartPoleState(0.3, -0.4, 99.0, 99.0);  // the plotted entries are not read
    const PolicyGrid grid = policyGrid(agent.table(), grid_params);
    ASSERT_EQ(23u * 23u, grid.points.size());
    const DiscretiserParams& bounds = params.discretiser;
    EXPECT_EQ(bounds.lower[2], grid.points.front().x);
    EXPECT_EQ(bounds.lower[3], grid.points.front().y);
    EXPECT_EQ(bounds.upper[2], grid.points.back().x);
    EXPECT_EQ(bounds.upper[3], grid.points.back().y);
    std::size_t ties = 0;
    for (const PolicyPoint& point : grid.points)
    {
      ActiveRows active;
      agent.activeRows(CartPoleState(0.3, -0.4, point.x, point.y), active);
      ASSERT_EQ(agent.greedyAction(active), point.action)
          << toString(params.features) << " " << point.x << " " << point.y;
      ASSERT_EQ(agent.value(active, point.action), point.value);
      ASSERT_EQ(agent.value(active, 0) == agent.value(active, 1), point.tie);
      ties += point.tie;
    }
    EXPECT_LT(ties, grid.points.size() / 10) << "the formula's values rarely tie";
  }
}

TEST(PolicyGridTest, ATableOfZerosHasNoPreferenceAnywhere)
{
  const QTable zeros(AgentParams().featureParams(), {-10.0, 10.0});
  for (const PolicyPoint& point : policyGrid(zeros, PolicyGridParams()).points)
  {
    ASSERT_TRUE(point.tie);
    ASSERT_EQ(0u, point.action) << "ties go to the lowest index, as the controller breaks them";
  }
}

TEST(PolicyGridTest, TheSliceAndThePreviousActionChooseTheRows)
{
  // Bins over x and theta: the policy at x = -2 and x = +2 are different rows of the table.
  AgentParams params;
  params.discretiser.bins = {{2, 1, 1, 2}};
  params.previous_action = true;
  QLearningAgent agent(params, 0);
  // Row layout: block (previous) * 4 + x bin * 2 + theta_dot bin; push right only in the right
  // half of the track after pushing left.
  const std::size_t block = 4;
  agent.table().at(1 * block + 2, 1) = 1.0;
  agent.table().at(1 * block + 3, 1) = 1.0;
  PolicyGridParams grid_params;
  grid_params.x_dimension = 0;
  grid_params.y_dimension = 2;
  grid_params.points = 4;
  grid_params.previous = 1;
  const PolicyGrid after_left = policyGrid(agent.table(), grid_params);
  for (const PolicyPoint& point : after_left.points)
    EXPECT_EQ(point.x > 0.0 ? 1u : 0u, point.action) << point.x;
  grid_params.previous = 0;
  for (const PolicyPoint& point : policyGrid(agent.table(), grid_params).points)
    EXPECT_TRUE(point.tie);
  grid_params.previous = 3;
  EXPECT_THROW(policyGrid(agent.table(), grid_params), std::invalid_argument);
}

TEST(PolicyGridTest, BadGridsAreRefusedNamingTheValue)
{
  const QTable table(AgentParams().featureParams(), {-10.0, 10.0});
  PolicyGridParams same;
  same.y_dimension = same.x_dimension;
  EXPECT_NE("", same.validate(2));
  PolicyGridParams one;
  one.points = 1;
  EXPECT_NE(std::string::npos, one.validate(2).find("points = 1"));
  PolicyGridParams nan;
  nan.slice[0] = std::nan("");
  EXPECT_NE(std::string::npos, nan.validate(2).find("x = nan"));
  EXPECT_THROW(policyGrid(table, one), std::invalid_argument);
  EXPECT_EQ(3u, stateDimension("theta_dot"));
  EXPECT_STREQ("x_dot", stateDimensionName(1));
  EXPECT_THROW(stateDimension("omega"), std::invalid_argument);
}

TEST(PolicyGridTest, TheCsvSaysWhatItIsThenOneRowPerPoint)
{
  QTable table(AgentParams().featureParams(), {-10.0, 10.0});
  table.episodes = 259;
  PolicyGridParams params;
  params.points = 3;
  const std::string csv = policyGridCsv(policyGrid(table, params), table);
  std::istringstream in(csv);
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(in, line))
    lines.push_back(line);
  ASSERT_EQ(6u + 1u + 9u, lines.size()) << csv;
  EXPECT_EQ("# features: bins (1x1x6x12 bins)", lines[1]);
  EXPECT_EQ("# episodes: 259", lines[2]);
  EXPECT_EQ("# actions: -10 10", lines[3]);
  EXPECT_EQ("# slice: x=0 x_dot=0", lines[4]);
  EXPECT_EQ("theta,theta_dot,action,effort,value,tie", lines[6]);
  EXPECT_EQ("0,0,0,-10,0,1", lines[11]) << "the middle point";
}

// A table's warp and mirror are in the configuration it carries, not in its header: the grid is
// what the agent that trained it chooses, on both sides of upright.
TEST(PolicyGridTest, AWarpedMirroredTableIsPlottedAsItsConfigurationSeesIt)
{
  TrainingConfig config;
  config.agent = tiles();
  config.agent.actions = {-10.0, 0.0, 10.0};
  config.agent.warp = {{1.0, 1.0, 2.0, 2.0}};
  config.agent.mirror = true;
  QLearningAgent agent = trainedLike(config.agent);
  agent.table().trained_with = trainingConfigText(config);
  PolicyGridParams grid_params;
  grid_params.points = 15;
  const PolicyGrid grid = policyGrid(agent.table(), grid_params);
  std::size_t mirrored = 0;
  for (const PolicyPoint& point : grid.points)
  {
    ActiveRows active;
    agent.activeRows(CartPoleState(0.0, 0.0, point.x, point.y), active);
    mirrored += active.mirrored ? 1 : 0;
    ASSERT_EQ(agent.greedyAction(active), point.action) << point.x << " " << point.y;
    ASSERT_EQ(agent.value(active, point.action), point.value);
  }
  EXPECT_GT(mirrored, 0u);
}
