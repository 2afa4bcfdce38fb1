#include "cartpole_qlearning/headless_trainer.h"

#include <chrono>

namespace cartpole_qlearning
{
HeadlessTrainer::HeadlessTrainer(const TrainingConfig& config, std::uint64_t seed)
  : config_(config),
    simulation_(config.physics, config.start_state_bound, seed),
    session_(config.task, config.agent, seed)
{
}

const EpisodeSummary& HeadlessTrainer::runEpisode()
{
  double effort = session_.beginEpisode(simulation_.resetRandom());
  for (;;)
  {
    const Decision decision = session_.observe(simulation_.step(effort));
    if (decision.episode_over)
      return session_.lastEpisode();
    effort = decision.effort;
  }
}

TrainingResult HeadlessTrainer::run(const std::function<void(const EpisodeSummary&)>& on_episode)
{
  const auto start = std::chrono::steady_clock::now();
  TrainingResult result;
  for (;;)
  {
    const EpisodeSummary& summary = runEpisode();
    result.episodes = summary.episode;
    result.steps = summary.total_steps;
    result.solved = result.solved || summary.solved;
    if (on_episode)
      on_episode(summary);
    if (config_.limits.reached(summary.episode, summary.solved))
      break;
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace cartpole_qlearning
