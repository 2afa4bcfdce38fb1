// The lockstep loop without ROS: the sim's and the controller's protocol classes wired to each
// other in one process, messages as function calls, the reset service as a call. Everything
// the nodes decide is decided here by the same classes in the same order, so its Q-table is
// the nodes' (and train_headless's) for a seed, and its cost per step is the protocol's own:
// the bound for the nodelet loop (bench/core_benchmark).
//
// Several robots: one simulation and one pair of protocols each, one shared learner, served in
// rounds as the learner node serves them: every robot's state of the round, in robot order.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <functional>
#include <memory>
#include <vector>

namespace cartpole_qlearning
{
class LockstepLoopback
{
public:
  // Robot r's simulation draws its start states from robotSeed(seed, r), as its sim node does.
  LockstepLoopback(const TrainingConfig& config, std::uint64_t seed, std::size_t robots = 1);

  // Trains until the limits are reached; on_episode is called after each episode.
  TrainingResult run(const std::function<void(const EpisodeSummary&)>& on_episode = {});

  const TrainingSession& session() const
  {
    return session_;
  }
  const SimProtocol& simProtocol(std::size_t robot = 0) const
  {
    return robots_.at(robot)->sim_protocol;
  }
  const ControllerProtocol& controllerProtocol(std::size_t robot = 0) const
  {
    return robots_.at(robot)->controller_protocol;
  }

private:
  struct Robot
  {
    Robot(const TrainingConfig& config, std::uint64_t seed, TrainingSession& session, std::size_t index);
    CartPoleSimulation simulation;
    SimProtocol sim_protocol;
    ControllerProtocol controller_protocol;
    Stamp stamp = 0;  // of the state waiting for the controller
  };

  TrainingSession session_;
  std::vector<std::unique_ptr<Robot>> robots_;
};

}  // namespace cartpole_qlearning
