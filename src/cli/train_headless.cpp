// train_headless: the controller node's application with the core alone (no ROS master): it
// trains (from scratch, from a table, or on from a run's checkpoint) or evaluates a table
// greedily, making the same RunApplication calls as the node, and prints what the node logs.
// Training ends with one line "until=U reached=B solved=B|n/a episodes=N steps=M train_s=T verdict_s=V"
// (train_mode.cpp), an evaluation
// with "evaluated=N balanced=M mean_return=R", a robustness suite (--evaluate TABLE --suite FILE)
// with "suite=PASSED|FAILED cases=N passed=K worst=M/E". With --replay it learns from the transitions of a
// file instead (the tutorial's worked example), tracing each update. --policy TABLE prints the
// table's greedy policy over a grid of states as CSV (scripts/plot_policy draws it); --average
// writes the mean of tables.
#include "headless_modes.h"

#include <cstdio>
#include <exception>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace
{
int run(const std::vector<std::string>& args)
{
  using namespace cartpole_qlearning;
  const HeadlessCommandLine line = parseHeadlessOptions(args);
  const HeadlessOptions& options = line.options;
  if (!line.error.empty())
  {
    std::cerr << "train_headless: " << line.error << "\n";
    if (line.usage_after_error)
      printHeadlessUsage(std::cerr);
    return 2;
  }
  if (options.help)
  {
    printHeadlessUsage(std::cout);
    return 0;
  }
  if (!options.policy_path.empty())
    return policyMode(options);
  if (!options.average_paths.empty())
    return averageMode(options);
  const std::optional<HeadlessSetup> setup = readHeadlessSetup(options);
  if (!setup)
    return 2;
  if (!options.suite_path.empty())
    return suiteMode(options, *setup);
  if (!options.replay_path.empty())
    return replayMode(options, *setup);
  return options.evaluating() ? evaluateMode(options, *setup) : trainMode(options, *setup);
}
}  // namespace

int main(int argc, char** argv)
{
  // Line by line, as the node logs: a log file followed with tail -f (or cut short by kill -9)
  // holds whole lines up to the last one said.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // What the checks did not foresee still ends with a message and exit 2, not an abort.
  try
  {
    return run(std::vector<std::string>(argv + 1, argv + argc));
  }
  catch (const std::exception& e)
  {
    std::cerr << "train_headless: " << e.what() << "\n";
    return 2;
  }
}
