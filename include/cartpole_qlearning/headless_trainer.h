// Training with the core alone: the simulation and the training session wired directly,
// one process, no messages. It makes the same calls in the same order as the simulator and
// controller nodes in lockstep, so a seed gives the same Q-table in both.
#pragma once

#include "cartpole_qlearning/cartpole_simulation.h"
#include "cartpole_qlearning/config.h"
#include "cartpole_qlearning/training_session.h"

#include <cstdint>
#include <functional>

namespace cartpole_qlearning
{
struct TrainingResult
{
  bool solved = false;
  std::uint64_t episodes = 0;  // episodes run
  std::uint64_t steps = 0;     // steps run
  double wall_s = 0.0;         // wall-clock seconds of the training loop
};

class HeadlessTrainer
{
public:
  HeadlessTrainer(const TrainingConfig& config, std::uint64_t seed);

  // One whole episode from a random start; returns its summary.
  const EpisodeSummary& runEpisode();

  // Episodes until solved (when limits.stop_when_solved) or limits.max_episodes; on_episode is
  // called after each one.
  TrainingResult run(const std::function<void(const EpisodeSummary&)>& on_episode = {});

  const TrainingSession& session() const
  {
    return session_;
  }
  TrainingSession& session()
  {
    return session_;
  }

private:
  TrainingConfig config_;
  CartPoleSimulation simulation_;
  TrainingSession session_;
};

}  // namespace cartpole_qlearning
