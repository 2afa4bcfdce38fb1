#include "cartpole_qlearning/lockstep_loopback.h"

#include <chrono>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
ControllerProtocolParams protocolParams(const TrainingConfig& config)
{
  ControllerProtocolParams params;
  params.limits = config.limits;
  return params;
}
}  // namespace

LockstepLoopback::LockstepLoopback(const TrainingConfig& config, std::uint64_t seed)
  : simulation_(config.physics, config.start_state_bound, seed),
    // No message is ever lost here, so no state is ever repeated.
    sim_protocol_(tickOf(config.physics.tau), WallClock::duration::max()),
    session_(config.task, config.agent, seed),
    controller_protocol_(session_, protocolParams(config))
{
}

TrainingResult LockstepLoopback::run(const std::function<void(const EpisodeSummary&)>& on_episode)
{
  // The wall clock matters only for repeats, and there are none: one time point serves.
  const WallClock::time_point now{};
  const auto start = std::chrono::steady_clock::now();
  TrainingResult result;
  // As cartpole_sim starts: a random start state, then the first stamp.
  simulation_.resetRandom();
  Stamp stamp = sim_protocol_.start(now);
  for (;;)
  {
    const Reaction reaction = controller_protocol_.onState(stamp, simulation_.state());
    if (reaction.episode_ended)
    {
      const EpisodeSummary& summary = session_.lastEpisode();
      result.episodes = summary.episode;
      result.steps = summary.total_steps;
      result.solved = result.solved || summary.solved;
      if (on_episode)
        on_episode(summary);
      if (reaction.training_finished)
        break;
    }
    if (reaction.request_reset)
    {
      simulation_.resetRandom();
      stamp = sim_protocol_.onReset(now);
      continue;
    }
    if (!reaction.answer || sim_protocol_.onCommand(reaction.stamp, now) != SimProtocol::Verdict::Step)
      throw std::logic_error("lockstep loopback: the controller's reaction does not move the sim on");
    simulation_.step(reaction.effort);
    stamp = sim_protocol_.pending();
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace cartpole_qlearning
