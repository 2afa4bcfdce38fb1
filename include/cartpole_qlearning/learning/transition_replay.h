// Transitions written by hand (state, action, reward, next state, in the names of a config's
// states), fed through the learner in order and traced, so that the tutorial's worked example,
// or a learner's own, runs through the same arithmetic as training. Epsilon-greedy would not
// draw the tutorial's actions: a replay chooses none, it only learns.
#pragma once

#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/trace.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// A replay file that cannot be used; the message names the file and the line.
class ReplayError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

struct ReplayTransition
{
  int line = 0;  // 1-based, in the file
  std::size_t state = 0;
  std::size_t action = 0;
  double reward = 0.0;
  std::size_t next_state = 0;  // a table row; unused when terminal
  bool terminal = false;       // the next state is the terminal one (names.back())
};

// Parses a replay document:
//   transitions:
//     - [S0 upright, A1, 1, S1 tilted left]   # state, action, reward, next state
// States by their names (stateNames(): one per row, then the terminal state, which may only be
// a next state); actions as A<k> or k, k < action_count; rewards finite numbers. Reads the whole
// document before returning: on the first problem it throws ReplayError naming the line.
std::vector<ReplayTransition> parseReplay(const std::string& text, const std::string& origin,
                                          const std::vector<std::string>& names, std::size_t action_count);
std::vector<ReplayTransition> loadReplay(const std::string& path, const std::vector<std::string>& names,
                                         std::size_t action_count);

// Feeds the transitions through agent.update in order, as training does: alpha from the agent's
// schedule at the table's episode count, the table's step count advanced at each transition and
// its episode count at each terminal one. on_step gets each transition with its trace;
// on_episode_end the number of the episode a terminal transition ended.
void replayTransitions(QLearningAgent& agent, const std::vector<ReplayTransition>& transitions,
                       const std::function<void(const ReplayTransition&, const TraceStep&)>& on_step,
                       const std::function<void(std::uint64_t episode)>& on_episode_end);

}  // namespace cartpole_qlearning
