#include "cartpole_qlearning/application/greedy_check.h"

#include "cartpole_qlearning/application/greedy_episodes.h"
#include "cartpole_qlearning/simulation/physics_engines.h"

#include <optional>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
GreedyCheck::GreedyCheck(const TrainingConfig& config, unsigned episodes, std::uint64_t seed)
  : episodes_(episodes),
    config_(config),
    simulation_(makeSimulation(config.physics, config.engine, config.start_state_bound, seed, config.perturbations))
{
  if (episodes < 1)
    throw std::invalid_argument("GreedyCheck: at least one episode");
  simulation_.setStart(config.task.start(config.start_state_bound));
}

bool GreedyCheck::passes(const QTable& table)
{
  std::optional<GreedyEpisodes> greedy;
  try
  {
    greedy.emplace(table, config_);
  }
  catch (const ConfigError& e)
  {
    throw std::invalid_argument(std::string("GreedyCheck: ") + e.what());
  }
  for (unsigned e = 0; e < episodes_; ++e)
  {
    const GreedyEpisode episode = greedy->run(simulation_);
    steps_run_ += episode.steps;
    if (!episode.balanced)
      return false;
  }
  return true;
}

}  // namespace cartpole_qlearning
