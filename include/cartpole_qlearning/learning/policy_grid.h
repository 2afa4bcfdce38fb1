// The greedy policy of a Q-table over a plane of the state space: at every point of a grid over
// two state dimensions (the other two held at a stated slice), the action the controller takes
// greedily and the value it expects, max_a Q. Each point goes through the table's own features
// and the learner's own greedy choice, so a picture of the grid is the policy the table holds,
// not a second reading of the file.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/q_table.h"

#include <cstddef>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The most points per axis: 1000 x 1000 looks up a million states, about a second.
constexpr std::size_t kMaxPolicyGridPoints = 1000;

struct PolicyGridParams
{
  std::size_t x_dimension = 2;  // across: theta
  std::size_t y_dimension = 3;  // up: theta_dot
  // Points per axis, spread evenly over the table's bounds of that dimension, both ends included.
  std::size_t points = 101;
  // The values of the dimensions not plotted; the plotted ones' entries are not read.
  CartPoleState slice = CartPoleState::Zero();
  // For a table that sees its previous action: 0 for none (an episode's first state), else 1 +
  // the action taken last, as QLearningAgent::activeRows takes it. Ignored by other tables.
  std::size_t previous = 0;

  // Empty when valid for a table with this many actions, else a message naming the bad value.
  std::string validate(std::size_t actions) const;
};

struct PolicyPoint
{
  double x = 0.0;
  double y = 0.0;
  std::size_t action = 0;  // the greedy action (ties: the lowest index, as the controller breaks them)
  double value = 0.0;      // max_a Q(s, a)
  // Every action has the same Q: the table holds no preference here (a bins state never
  // visited is all zeros); the controller would take action 0.
  bool tie = false;
};

struct PolicyGrid
{
  PolicyGridParams params;
  double x_lower = 0.0, x_upper = 0.0, y_lower = 0.0, y_upper = 0.0;
  // Row by row from y_lower up, each from x_lower across: points[j * params.points + i].
  std::vector<PolicyPoint> points;
};

// The grid over the table's bounds of the two dimensions. Throws std::invalid_argument with
// validate()'s message.
PolicyGrid policyGrid(const QTable& table, const PolicyGridParams& params);

// The grid as CSV: '#' lines saying what it is (features, actions, slice, bounds), then the
// header "<x name>,<y name>,action,effort,value,tie" and one row per point, numbers with 17
// significant digits so that the text is the same on every machine that computes the same doubles.
std::string policyGridCsv(const PolicyGrid& grid, const QTable& table);

}  // namespace cartpole_qlearning
