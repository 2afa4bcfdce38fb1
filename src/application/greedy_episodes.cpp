#include "cartpole_qlearning/application/greedy_episodes.h"

#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
GreedyEpisodes::GreedyEpisodes(const QTable& table, const TrainingConfig& config, unsigned predict_delay_steps)
  : table_(checkedTable(table, config)),
    task_(config.task),
    features_(config.agent.featureParams(), config.agent.actions.size()),
    efforts_(table.actions()),
    predictor_(config.physics, predict_delay_steps),
    predicting_(predict_delay_steps > 0),
    decision_steps_(config.agent.decision_steps)
{
}

GreedyEpisode GreedyEpisodes::run(CartPoleSimulation& simulation)
{
  simulation.resetRandom();
  // The model the table learnt, for a prediction of the robot's delay (none: decide for what is seen).
  predictor_.begin(simulation.observation());
  features_.activeRows(predicting_ ? predictor_.predict(simulation.observation()) : simulation.observation(), rows_);
  std::size_t action = QLearningAgent::greedyAction(table_, rows_);
  GreedyEpisode episode;
  StepOutcome outcome;
  for (;;)
  {
    predictor_.sent(efforts_[action]);
    simulation.step(efforts_[action]);
    outcome = task_.evaluate(simulation.observation(), ++episode.steps, efforts_[action]);
    episode.episode_return += outcome.score;
    if (outcome.done())
      break;
    predictor_.observed(simulation.observation());
    // Within a decision period the action is held (as TrainingSession holds it).
    if (episode.steps % decision_steps_ != 0)
      continue;
    // The action just taken is part of what a previous_action table sees of the state.
    features_.activeRows(predicting_ ? predictor_.predict(simulation.observation()) : simulation.observation(), rows_,
                         action + 1);
    action = QLearningAgent::greedyAction(table_, rows_);
  }
  episode.balanced = outcome.truncated && !outcome.terminated;
  return episode;
}

const QTable& GreedyEpisodes::checkedTable(const QTable& table, const TrainingConfig& config)
{
  const std::string invalid = config.agent.validate();
  if (!invalid.empty())
    throw std::invalid_argument(invalid);
  const std::string mismatch = tableShapeMismatch(config.agent.featureParams(), config.agent.actions, table);
  if (!mismatch.empty())
    throw ConfigError("the table does not fit the configuration: " + mismatch);
  return table;
}

}  // namespace cartpole_qlearning
