// Tabular Q-learning with epsilon-greedy exploration over a fixed set of efforts.
#pragma once

#include "cartpole_qlearning/discretiser.h"
#include "cartpole_qlearning/q_table.h"
#include "cartpole_qlearning/random.h"
#include "cartpole_qlearning/schedule.h"

#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
struct AgentParams
{
  DiscretiserParams discretiser;
  std::vector<double> actions{-10.0, 10.0};   // [N] the effort of each action
  double gamma = 0.99;                        // discount, in [0, 1]
  ScheduleParams epsilon = defaultEpsilon();  // exploration rate per episode
  ScheduleParams alpha = defaultAlpha();      // learning rate per episode
  // Names of the table's rows for the trace, then the name of the terminal state (which has no
  // row: its Q is 0); empty: S0 ... S<n-1> and "fallen". Display only: not part of the table.
  std::vector<std::string> state_names;

  // The defaults of config/cartpole.yaml (why: its comments): epsilon linear from 1.0 to 0.03
  // over 150 episodes, alpha on the log schedule from 1.0 to 0.05 over ~150.
  static ScheduleParams defaultEpsilon();
  static ScheduleParams defaultAlpha();

  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
};

// What one update did, in the tutorial's terms: Q(s,a) went from old_value to
// new_value = old_value + alpha * (target - old_value), with target = reward + gamma * next_max
// (next_max = max_a' Q(s',a'), 0 and unused when the next state is terminal).
struct QUpdate
{
  double old_value = 0.0;
  double next_max = 0.0;
  double target = 0.0;
  double new_value = 0.0;
};

class QLearningAgent
{
public:
  // The exploration draws come from the agent's own stream of this seed.
  QLearningAgent(const AgentParams& params, std::uint64_t seed);

  const AgentParams& params() const
  {
    return params_;
  }
  const Discretiser& discretiser() const
  {
    return discretiser_;
  }
  const QTable& table() const
  {
    return table_;
  }
  QTable& table()
  {
    return table_;
  }

  double epsilon(unsigned long episode) const
  {
    return epsilon_.value(episode);
  }
  double alpha(unsigned long episode) const
  {
    return alpha_.value(episode);
  }

  // With probability epsilon a uniformly drawn action, else the greedy one. Always takes one
  // draw for the coin and, when exploring, one for the action.
  std::size_t selectAction(std::size_t state, double epsilon);
  std::size_t greedyAction(std::size_t state) const
  {
    return table_.argmax(state);
  }

  // Q(s,a) += alpha * (reward + gamma * max_a' Q(s',a') - Q(s,a)); the max term is dropped when
  // next_is_terminal (a fall has no future), kept on truncation. Returns what it did (the trace).
  QUpdate update(std::size_t state, std::size_t action, double reward, std::size_t next_state, bool next_is_terminal,
                 double alpha);

  // Replaces the table after checking it has this agent's discretisation and actions; on a
  // mismatch returns what differs and leaves the table in use as it was.
  std::string replaceTable(QTable table);

private:
  AgentParams params_;
  Discretiser discretiser_;
  Schedule epsilon_;
  Schedule alpha_;
  QTable table_;
  RandomStream rng_;
};

}  // namespace cartpole_qlearning
