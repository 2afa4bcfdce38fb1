// The lockstep loop without ROS: the sim's and the controller's protocol classes wired to each
// other in one process, messages as function calls, the reset service as a call. Everything
// the two nodes decide is decided here by the same classes in the same order, so its Q-table
// is the nodes' (and train_headless's) for a seed, and its cost per step is the protocol's own:
// the bound for the nodelet loop (bench/core_benchmark).
#pragma once

#include "cartpole_qlearning/cartpole_simulation.h"
#include "cartpole_qlearning/config.h"
#include "cartpole_qlearning/headless_trainer.h"
#include "cartpole_qlearning/lockstep_protocol.h"
#include "cartpole_qlearning/training_session.h"

#include <functional>

namespace cartpole_qlearning
{
class LockstepLoopback
{
public:
  LockstepLoopback(const TrainingConfig& config, std::uint64_t seed);

  // Trains until the limits are reached; on_episode is called after each episode.
  TrainingResult run(const std::function<void(const EpisodeSummary&)>& on_episode = {});

  const TrainingSession& session() const
  {
    return session_;
  }
  const SimProtocol& simProtocol() const
  {
    return sim_protocol_;
  }
  const ControllerProtocol& controllerProtocol() const
  {
    return controller_protocol_;
  }

private:
  CartPoleSimulation simulation_;
  SimProtocol sim_protocol_;
  TrainingSession session_;
  ControllerProtocol controller_protocol_;
};

}  // namespace cartpole_qlearning
