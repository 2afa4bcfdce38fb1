#include "lockstep_loopback.h"

#include "cartpole_qlearning/simulation/physics_engines.h"

#include <chrono>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
ControllerProtocolParams protocolParams(const TrainingConfig& config, std::size_t robot)
{
  ControllerProtocolParams params;
  params.limits = config.limits;
  params.robot = robot;
  return params;
}
}  // namespace

LockstepLoopback::Robot::Robot(const TrainingConfig& config, std::uint64_t seed, TrainingSession& session,
                               std::size_t index)
  : simulation(makeSimulation(config.physics, config.engine, config.start_state_bound, robotSeed(seed, index),
                              config.perturbations)),
    // No message is ever lost here, so no state is ever repeated.
    sim_protocol(tickOf(config.physics.tau), WallClock::duration::max()),
    controller_protocol(session, protocolParams(config, index))
{
}

LockstepLoopback::LockstepLoopback(const TrainingConfig& config, std::uint64_t seed, std::size_t robots)
  : session_(config.task, config.agent, seed, true, robots)
{
  for (std::size_t r = 0; r < robots; ++r)
    robots_.push_back(std::make_unique<Robot>(config, seed, session_, r));
}

TrainingResult LockstepLoopback::run(const std::function<void(const EpisodeSummary&)>& on_episode)
{
  // The wall clock matters only for repeats, and there are none: one time point serves.
  const WallClock::time_point now{};
  const auto start = std::chrono::steady_clock::now();
  TrainingResult result;
  // As cartpole_sim starts: a random start state, then the first stamp.
  for (auto& robot : robots_)
  {
    robot->simulation.resetRandom();
    robot->stamp = robot->sim_protocol.start(now);
  }
  for (;;)
  {
    for (auto& robot : robots_)
    {
      const Reaction reaction = robot->controller_protocol.onState(robot->stamp, robot->simulation.observation());
      if (reaction.episode_ended)
      {
        const EpisodeSummary& summary = session_.lastEpisode();
        result.record(summary);
        if (on_episode)
          on_episode(summary);
        if (reaction.training_finished)
        {
          result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          return result;
        }
      }
      if (reaction.request_reset)
      {
        robot->simulation.resetRandom();
        robot->stamp = robot->sim_protocol.onReset(now);
        continue;
      }
      if (!reaction.answer || robot->sim_protocol.onCommand(reaction.stamp, now) != SimProtocol::Verdict::Step)
        throw std::logic_error("lockstep loopback: the controller's reaction does not move the sim on");
      robot->simulation.step(reaction.effort);
      robot->stamp = robot->sim_protocol.pending();
    }
  }
}

}  // namespace cartpole_qlearning
