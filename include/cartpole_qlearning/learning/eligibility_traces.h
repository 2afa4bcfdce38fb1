// Eligibility traces over a table's weights, for Watkins's Q(lambda) (Sutton and Barto,
// Reinforcement Learning, 2nd ed., section 12.10): each (row, action) weight an episode has
// updated lately keeps a trace that fades by gamma * lambda a decision, and every TD error moves
// each traced weight by its trace. A reward then reaches the decisions that led to it in one
// step instead of creeping back one decision per visit: what a swing-up, whose reward comes
// seconds after the pushes that earn it, needs.
#pragma once

#include "cartpole_qlearning/learning/features.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cartpole_qlearning
{
class EligibilityTraces
{
public:
  // A trace below this is dropped: it would move its weight by less than a hundredth of what
  // a visit does, and the list of traces stays short (tilings x a few dozen decisions).
  static constexpr double kFloor = 0.01;

  void clear();
  // The weights the state activates for the action, just visited: replacing traces, each set to 1
  // (a weight visited again does not pile up past 1). values: how many weights the table holds
  // (rows x actions).
  void visit(const ActiveRows& state, std::size_t action, std::size_t actions, std::size_t values);
  // Every trace times factor (gamma * lambda); those below kFloor dropped.
  void decay(double factor);

  std::size_t size() const
  {
    return indices_.size();
  }
  // The traced weights: their index in the table's values (row * actions + action) and trace.
  const std::vector<std::uint32_t>& indices() const
  {
    return indices_;
  }
  const std::vector<double>& traces() const
  {
    return traces_;
  }
  // The trace of one weight (0 when it has none).
  double trace(std::size_t index) const;

private:
  std::vector<std::uint32_t> indices_;
  std::vector<double> traces_;
  // Where each weight's trace sits in indices_ (-1: none): a visit finds it without a search.
  std::vector<std::int32_t> slot_;
};

}  // namespace cartpole_qlearning
