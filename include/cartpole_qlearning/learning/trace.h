// The trace: each Q-learning update written out as the tutorial works it by hand (state,
// action, reward, next state, old Q, target, new Q) and the table at an episode's end, so a
// learner can follow the arithmetic on the running nodes. One formatter for train_headless
// (--trace, --replay) and the controller (~trace).
#pragma once

#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/q_table.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// One update, as the learner made it.
struct TraceStep
{
  // The episode's number as its EpisodeSummary will give it: `episode` when one robot feeds the
  // learner, `robot_episode` when several do.
  std::uint64_t episode = 0;
  unsigned step = 0;  // 1-based, within the episode
  std::size_t state = 0;
  std::size_t action = 0;
  double reward = 0.0;
  std::size_t next_state = 0;  // not shown when terminal: the terminal state is named instead
  bool terminal = false;
  bool truncated = false;  // the step limit: the episode ends but the target bootstraps
  double alpha = 0.0;
  double gamma = 0.0;
  QUpdate update;
};

// The names the trace gives the table's rows, then the terminal state's name (one more than
// the rows): params.state_names when set, else S0 ... S<n-1> and "fallen".
std::vector<std::string> stateNames(const AgentParams& params);

// A number as the trace prints it: 12 significant digits, so that the tutorial's exact values
// (1.71037015625) print exactly and a reader can redo the arithmetic.
std::string traceNumber(double value);

// "A1 (+10 N)": the action's index, as a replay file names it, and its effort.
std::string actionName(std::size_t action, const std::vector<double>& efforts);

// One line:
//   episode 1 step 2: S1 --A0 (-10 N)--> S0, r = 1; target = 1 + 0.9 * 0.5 = 1.45; Q(S1, A0) = 0 + 0.5 * (1.45 - 0) =
//   0.725
// and on a fall "--> fallen (terminal), r = -1; target = -1 (no future); ...".
std::string traceLine(const TraceStep& step, const std::vector<std::string>& names, const std::vector<double>& efforts);

// The table, a header line and one line per row in row order, then the terminal state's line
// (all zeros: a fall has no future). No trailing newline.
std::string qTableText(const QTable& table, const std::vector<std::string>& names);

}  // namespace cartpole_qlearning
