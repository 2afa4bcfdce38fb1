// Training with the core alone: the simulations and the training session wired directly,
// one process, no messages. It makes the same calls in the same order as the simulator and
// controller nodes in lockstep, so a seed gives the same Q-table in both. With several robots
// it serves them in rounds, as the learner node does in lockstep: in each round every robot's
// next state, in robot order (a robot whose episode ended starts its next one in the round
// after, from the start state its reset drew).
#pragma once

#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
struct TrainingResult
{
  bool solved = false;
  std::uint64_t episodes = 0;  // episodes run
  std::uint64_t steps = 0;     // steps run
  double wall_s = 0.0;         // wall-clock seconds of the training loop

  // Counts an episode that just ended.
  void record(const EpisodeSummary& summary)
  {
    episodes = summary.episode;
    steps = summary.total_steps;
    solved = solved || summary.solved;
  }
};

// The seed of robot r's start states: the run's seed for robot 0 (so one robot is today's
// single sim), then one more per robot. The sims of train.launch robots:=N get these.
inline std::uint64_t robotSeed(std::uint64_t seed, std::size_t robot)
{
  return seed + robot;
}

class HeadlessTrainer
{
public:
  // learning = false: greedy, no updates (an evaluation). The simulations run on the config's
  // engine: throws EngineError when it cannot be made (physics_engines.h).
  HeadlessTrainer(const TrainingConfig& config, std::uint64_t seed, std::size_t robots = 1, bool learning = true);

  // Robot 0 alone: one whole episode from a random start; returns its summary.
  const EpisodeSummary& runEpisode();

  // Rounds until solved (when limits.stop_when_solved) or limits.max_episodes; on_episode is
  // called after each episode.
  TrainingResult run(const std::function<void(const EpisodeSummary&)>& on_episode = {});
  // Rounds until `finished` returns true after an episode (the caller decides: the application's
  // limits, an evaluation's verdict) or until `stop` is set (looked at every round: Ctrl-C), the
  // episodes under way then left unfinished.
  TrainingResult runUntil(const std::function<bool(const EpisodeSummary&)>& finished,
                          const std::atomic<bool>* stop = nullptr);

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
  std::vector<CartPoleSimulation> simulations_;
  TrainingSession session_;
};

}  // namespace cartpole_qlearning
