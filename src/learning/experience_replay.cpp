#include "cartpole_qlearning/learning/experience_replay.h"

#include <algorithm>
#include <stdexcept>

namespace cartpole_qlearning
{
ExperienceReplay::ExperienceReplay(std::size_t capacity, std::uint64_t seed)
  : capacity_(capacity), rng_(seed, kReplayStream)
{
  if (capacity_ < 1)
    throw std::invalid_argument("ExperienceReplay: a capacity of at least one transition");
}

void ExperienceReplay::add(const ActiveRows& state, std::size_t action, double reward, const ActiveRows& next_state,
                           bool next_is_terminal)
{
  if (rows_per_state_ == 0)
  {
    rows_per_state_ = state.count;
    // Grown as transitions come, up to the capacity: a short run does not hold a full buffer.
    rows_.reserve(std::min<std::size_t>(capacity_, 4096) * 2 * rows_per_state_);
  }
  if (state.count != rows_per_state_ || next_state.count != rows_per_state_)
    throw std::invalid_argument("ExperienceReplay: every state must activate as many rows as the first");
  if (size_ < capacity_)
  {
    rows_.insert(rows_.end(), state.rows.begin(), state.rows.begin() + rows_per_state_);
    rows_.insert(rows_.end(), next_state.rows.begin(), next_state.rows.begin() + rows_per_state_);
    actions_.push_back(static_cast<std::uint16_t>(action));
    rewards_.push_back(reward);
    terminal_.push_back(next_is_terminal ? 1 : 0);
    ++size_;
  }
  else
  {
    std::uint32_t* slot = &rows_[next_slot_ * 2 * rows_per_state_];
    std::copy(state.rows.begin(), state.rows.begin() + rows_per_state_, slot);
    std::copy(next_state.rows.begin(), next_state.rows.begin() + rows_per_state_, slot + rows_per_state_);
    actions_[next_slot_] = static_cast<std::uint16_t>(action);
    rewards_[next_slot_] = reward;
    terminal_[next_slot_] = next_is_terminal ? 1 : 0;
  }
  next_slot_ = (next_slot_ + 1) % capacity_;
}

const ReplayedTransition& ExperienceReplay::draw()
{
  if (size_ == 0)
    throw std::logic_error("ExperienceReplay: nothing to draw from");
  const auto slot = static_cast<std::size_t>(rng_.uniformIndex(size_));
  const std::uint32_t* rows = &rows_[slot * 2 * rows_per_state_];
  std::copy(rows, rows + rows_per_state_, drawn_.state.rows.begin());
  std::copy(rows + rows_per_state_, rows + 2 * rows_per_state_, drawn_.next_state.rows.begin());
  drawn_.state.count = rows_per_state_;
  drawn_.next_state.count = rows_per_state_;
  drawn_.action = actions_[slot];
  drawn_.reward = rewards_[slot];
  drawn_.next_is_terminal = terminal_[slot] != 0;
  return drawn_;
}

}  // namespace cartpole_qlearning
