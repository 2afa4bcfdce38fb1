#include "cartpole_qlearning/training_session.h"

#include <cstdio>

namespace cartpole_qlearning
{
std::string progressLine(const EpisodeSummary& s, unsigned window, double steps_per_second, double elapsed_s)
{
  char line[160];
  std::snprintf(line, sizeof line,
                "episode %6llu  mean_return_%u %7.2f  epsilon %.3f  alpha %.3f  steps/s %9.0f  time %.2f s",
                static_cast<unsigned long long>(s.episode), window, s.mean_return_window, s.epsilon, s.alpha,
                steps_per_second, elapsed_s);
  return line;
}

TrainingSession::TrainingSession(const TaskParams& task, const AgentParams& agent, std::uint64_t seed, bool learning)
  : task_(task), agent_(agent, seed), learning_(learning)
{
}

std::size_t TrainingSession::chooseAction(std::size_t state)
{
  return learning_ ? agent_.selectAction(state, epsilon_) : agent_.greedyAction(state);
}

double TrainingSession::beginEpisode(const CartPoleState& start_state)
{
  // Schedules count every episode the table has seen, so a loaded table resumes where it was.
  const std::uint64_t episode = agent_.table().episodes;
  epsilon_ = learning_ ? agent_.epsilon(episode) : 0.0;
  alpha_ = learning_ ? agent_.alpha(episode) : 0.0;
  in_episode_ = true;
  steps_ = 0;
  return_ = 0.0;
  state_ = agent_.discretiser().index(start_state);
  action_ = chooseAction(state_);
  return agent_.table().actions()[action_];
}

Decision TrainingSession::observe(const CartPoleState& state)
{
  Decision decision;
  ++steps_;
  decision.outcome = task_.evaluate(state, steps_);
  return_ += decision.outcome.reward;
  const std::size_t next_state = agent_.discretiser().index(state);
  if (learning_)
  {
    agent_.update(state_, action_, decision.outcome.reward, next_state, decision.outcome.terminated, alpha_);
    ++agent_.table().steps;
  }

  if (!decision.outcome.done())
  {
    state_ = next_state;
    action_ = chooseAction(state_);
    decision.action = action_;
    decision.effort = agent_.table().actions()[action_];
    return decision;
  }

  decision.episode_over = true;
  in_episode_ = false;
  if (learning_)
    ++agent_.table().episodes;

  const unsigned window = task_.params().solved_window;
  window_.push_back(return_);
  window_sum_ += return_;
  if (window_.size() > window)
  {
    window_sum_ -= window_.front();
    window_.pop_front();
  }
  last_.episode += 1;
  last_.steps = steps_;
  last_.episode_return = return_;
  last_.mean_return_window = window_sum_ / static_cast<double>(window_.size());
  last_.epsilon = epsilon_;
  last_.alpha = alpha_;
  last_.terminated = decision.outcome.terminated;
  last_.truncated = decision.outcome.truncated;
  last_.solved = window_.size() == window && last_.mean_return_window >= task_.params().solved_mean_return;
  last_.total_steps += steps_;
  return decision;
}

std::string TrainingSession::replaceTable(QTable table)
{
  return agent_.replaceTable(std::move(table));
}

}  // namespace cartpole_qlearning
