// A greedy evaluation during training, the measure the field's learning curves use (TD3's paper
// evaluates every 5,000 steps): the table as it stands runs greedily, learning nothing, for a few
// episodes of the task's full length on a simulation of its own (its own seed: training's draws
// are untouched); it passes when every episode balances to max_episode_steps. train_headless
// --greedy-check N runs it after each training episode until it first passes and says at which
// step.
#pragma once

#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <cstdint>

namespace cartpole_qlearning
{
// The check's starts for a run of `seed`: apart from every robot's (headless_trainer.h's robotSeed).
inline std::uint64_t greedyCheckSeed(std::uint64_t seed)
{
  return seed + 1000000;
}

class GreedyCheck
{
public:
  // episodes >= 1; seed: the check's starts (apart from training's). Throws EngineError when the
  // config's engine cannot be made.
  GreedyCheck(const TrainingConfig& config, unsigned episodes, std::uint64_t seed);

  // Runs `table` greedily (greedy_episodes.h), episode by episode, stopping at the first that
  // falls: true when all of them balanced to the step limit. Each call starts where the last left
  // the check's starts. Throws std::invalid_argument when the table does not fit the configuration.
  bool passes(const QTable& table);
  // Steps run by every call so far (none of them training's).
  std::uint64_t stepsRun() const
  {
    return steps_run_;
  }

private:
  unsigned episodes_;
  TrainingConfig config_;
  CartPoleSimulation simulation_;
  std::uint64_t steps_run_ = 0;
};

}  // namespace cartpole_qlearning
