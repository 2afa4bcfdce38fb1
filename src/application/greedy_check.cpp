#include "cartpole_qlearning/application/greedy_check.h"

#include <stdexcept>

namespace cartpole_qlearning
{
GreedyCheck::GreedyCheck(const TrainingConfig& config, unsigned episodes, std::uint64_t seed)
  : episodes_(episodes), trainer_(config, seed, 1, false)
{
  if (episodes < 1)
    throw std::invalid_argument("GreedyCheck: at least one episode");
}

bool GreedyCheck::passes(const QTable& table)
{
  const std::string mismatch = trainer_.session().replaceTable(table);
  if (!mismatch.empty())
    throw std::invalid_argument("GreedyCheck: the table does not fit the configuration: " + mismatch);
  for (unsigned e = 0; e < episodes_; ++e)
  {
    const EpisodeSummary& s = trainer_.runEpisode();
    steps_run_ += s.steps;
    if (s.terminated || !s.truncated)
      return false;
  }
  return true;
}

}  // namespace cartpole_qlearning
