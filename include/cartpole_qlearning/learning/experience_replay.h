// Experience replay for the table: the transitions a training session has learnt from, kept in a
// ring of fixed capacity and drawn again at random for further one-step updates, as the off-policy
// learners of the Control Suite's benchmarks do from their buffers (DQN, SAC, TD-MPC2 update many
// times per environment step). Every stored transition is a real step of the environment, its
// reward the task's own: replaying one takes no step, so the environment's step count is the same
// with or without replay. What it buys is sample efficiency: a rare success (a pole held upright
// for a second) is learnt from many times instead of once, and its value spreads back through the
// states that lead to it without waiting for the table to visit them again.
#pragma once

#include "cartpole_qlearning/common/random.h"
#include "cartpole_qlearning/learning/features.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cartpole_qlearning
{
// The replay's draws: a stream of its own, so that exploration (the agent's) and the start states
// (the environment's) draw what they drew without replay.
constexpr std::uint64_t kReplayStream = 4;

// One transition as the learner saw it: the rows of the state the action was taken in and of the
// state it led to, the summed reward of its decision period, and whether that state ended the task.
struct ReplayedTransition
{
  ActiveRows state;
  std::size_t action = 0;
  double reward = 0.0;
  ActiveRows next_state;
  bool next_is_terminal = false;
};

class ExperienceReplay
{
public:
  // capacity: the transitions kept (the oldest is overwritten once it is full), at least 1.
  ExperienceReplay(std::size_t capacity, std::uint64_t seed);

  // Every transition stored must activate as many rows as the first one did (a session's features
  // do not change), so that they are kept in one flat array.
  void add(const ActiveRows& state, std::size_t action, double reward, const ActiveRows& next_state,
           bool next_is_terminal);
  // A stored transition drawn uniformly (one draw of the replay's stream); the buffer must not be empty.
  const ReplayedTransition& draw();

  std::size_t size() const
  {
    return size_;
  }
  std::size_t capacity() const
  {
    return capacity_;
  }

private:
  std::size_t capacity_;
  std::size_t size_ = 0;
  std::size_t next_slot_ = 0;  // where the next transition goes: the oldest once full
  unsigned rows_per_state_ = 0;
  // Per slot: the state's rows, then the next state's (2 * rows_per_state_ a slot).
  std::vector<std::uint32_t> rows_;
  std::vector<std::uint16_t> actions_;
  std::vector<double> rewards_;
  std::vector<std::uint8_t> terminal_;
  RandomStream rng_;
  ReplayedTransition drawn_;
};

}  // namespace cartpole_qlearning
