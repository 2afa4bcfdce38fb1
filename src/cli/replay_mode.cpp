#include "headless_modes.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/trace.h"
#include "cartpole_qlearning/learning/transition_replay.h"

#include <cstdio>
#include <iostream>

namespace cartpole_qlearning
{
// --replay FILE: learns from the file's transitions alone (the tutorial's worked example), tracing
// each update. Exit 2 on a bad file (every line is checked before the first update, so a bad file
// changes nothing), 1 when --save's table cannot be written.
int replayMode(const HeadlessOptions& options, const HeadlessSetup& setup)
{
  const TrainingConfig& config = setup.config;
  const std::string& replay_path = options.replay_path;
  const std::vector<std::string> names = stateNames(config.agent);
  std::vector<ReplayTransition> transitions;
  try
  {
    transitions = loadReplay(replay_path, names, config.agent.actions.size());
  }
  catch (const ReplayError& e)
  {
    std::cerr << "train_headless: " << e.what() << "\n";
    return 2;
  }
  QLearningAgent agent(config.agent, options.seed.value_or(0));
  std::printf("replaying %zu transitions of %s (gamma %s, alpha %s at episode 1)\n", transitions.size(),
              replay_path.c_str(), traceNumber(config.agent.gamma).c_str(), traceNumber(agent.alpha(0)).c_str());
  std::size_t number = 0;
  replayTransitions(
      agent, transitions,
      [&](const ReplayTransition& t, const TraceStep& step) {
        std::printf("#%zu (line %d) %s\n", ++number, t.line, traceLine(step, names, config.agent.actions).c_str());
      },
      [&](std::uint64_t episode) {
        std::printf("Q-table after episode %llu:\n%s\n", static_cast<unsigned long long>(episode),
                    qTableText(agent.table(), names).c_str());
      });
  std::printf("Q-table after transition %zu (the end of the replay):\n%s\n", transitions.size(),
              qTableText(agent.table(), names).c_str());
  const std::string& save_path = options.save_path;
  if (save_path.empty())
    return 0;
  // What it takes to run it, as every saved table says (training_session.h's stampTables).
  agent.table().tau = config.physics.tau;
  agent.table().trained_with = trainingConfigText(config);
  try
  {
    saveTable(agent.table(), setup.table_dir, save_path);
    if (!options.quiet)
      std::printf("saved the Q-table to %s\n", tablePath(setup.table_dir, save_path).c_str());
  }
  catch (const FileError& e)
  {
    std::cerr << "train_headless: --save: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace cartpole_qlearning
