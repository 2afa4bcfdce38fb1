// Greedy episodes: a table run as it stands, learning nothing and exploring nothing, on a
// simulation the caller owns. What every verdict runs: the robustness suite's cases
// (suite_runner.h) and the greedy check during training (greedy_check.h).
#pragma once

#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <vector>

namespace cartpole_qlearning
{
struct GreedyEpisode
{
  unsigned steps = 0;
  double episode_return = 0.0;  // the return the solved window counts (TaskParams::scoreReward())
  bool balanced = false;        // reached the task's step limit without falling
};

// The steps a TrainingSession that does not learn takes (the same rows, the same first-best action,
// the same task, the return summed in the same order), without its bookkeeping (the learning
// branch, the solved window, episode summaries) or an agent that holds a copy of the table.
class GreedyEpisodes
{
public:
  // config: the task (step limit, thresholds, reward) and the agent's features and actions the
  // table was made for. predict_delay_steps: each decision for the state the config's physics
  // predicts this many steps ahead (DelayPredictor); 0: for the state observed. The table must
  // outlive this. Throws ConfigError when the table does not fit the configuration.
  GreedyEpisodes(const QTable& table, const TrainingConfig& config, unsigned predict_delay_steps = 0);

  // One episode from the simulation's next random reset.
  GreedyEpisode run(CartPoleSimulation& simulation);

private:
  static const QTable& checkedTable(const QTable& table, const TrainingConfig& config);

  const QTable& table_;
  const CartPoleTask task_;
  const FeatureMap features_;
  const std::vector<double>& efforts_;
  DelayPredictor predictor_;
  const bool predicting_;
  const unsigned decision_steps_;
  ActiveRows rows_;
};

}  // namespace cartpole_qlearning
