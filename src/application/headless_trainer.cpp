#include "cartpole_qlearning/application/headless_trainer.h"

#include "cartpole_qlearning/simulation/physics_engines.h"

#include <chrono>

namespace cartpole_qlearning
{
HeadlessTrainer::HeadlessTrainer(const TrainingConfig& config, std::uint64_t seed, std::size_t robots, bool learning)
  : config_(config), session_(config.task, config.agent, seed, learning, robots)
{
  simulations_.reserve(robots);
  for (std::size_t r = 0; r < robots; ++r)
  {
    simulations_.push_back(makeSimulation(config.physics, config.engine, config.start_state_bound, robotSeed(seed, r),
                                          config.perturbations));
    simulations_.back().setStart(config.task.start(config.start_state_bound));
  }
}

const EpisodeSummary& HeadlessTrainer::runEpisode()
{
  CartPoleSimulation& simulation = simulations_.front();
  simulation.resetRandom();
  // The learner sees what the sensors read (the true state when they are not noisy).
  double effort = session_.beginEpisode(simulation.observation());
  for (;;)
  {
    simulation.step(effort);
    const Decision decision = session_.observe(simulation.observation());
    if (decision.episode_over)
      return session_.lastEpisode();
    effort = decision.effort;
  }
}

TrainingResult HeadlessTrainer::run(const std::function<void(const EpisodeSummary&)>& on_episode)
{
  return runUntil([&](const EpisodeSummary& summary) {
    if (on_episode)
      on_episode(summary);
    return config_.limits.reached(summary.episode, summary.solved);
  });
}

TrainingResult HeadlessTrainer::runUntil(const std::function<bool(const EpisodeSummary&)>& finished,
                                         const std::atomic<bool>* stop)
{
  const auto start = std::chrono::steady_clock::now();
  TrainingResult result;
  // As each sim starts: a random start state. The episodes begin in the first round.
  std::vector<double> efforts(simulations_.size(), 0.0);
  for (CartPoleSimulation& simulation : simulations_)
    simulation.resetRandom();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  for (;;)
  {
    if (stop != nullptr && stop->load(std::memory_order_relaxed))
    {
      result.wall_s = elapsed();
      return result;
    }
    for (std::size_t r = 0; r < simulations_.size(); ++r)
    {
      CartPoleSimulation& simulation = simulations_[r];
      if (!session_.inEpisode(r))
      {
        // The learner sees what the sensors read (the true state when they are not noisy).
        efforts[r] = session_.beginEpisode(simulation.observation(), r);
        continue;
      }
      simulation.step(efforts[r]);
      const Decision decision = session_.observe(simulation.observation(), r);
      if (!decision.episode_over)
      {
        efforts[r] = decision.effort;
        continue;
      }
      const EpisodeSummary& summary = session_.lastEpisode();
      result.record(summary);
      if (finished(summary))
      {
        result.wall_s = elapsed();
        return result;
      }
      simulation.resetRandom();  // the sim's reset; the next episode begins in the next round
    }
  }
}

}  // namespace cartpole_qlearning
