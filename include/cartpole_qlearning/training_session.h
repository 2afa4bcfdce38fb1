// What the controller does with each state it receives: judge the last step with the task,
// learn from it, choose the next action, and keep the episode statistics. The controller node
// and the headless trainer both drive this class, so they learn identically.
#pragma once

#include "cartpole_qlearning/cartpole_task.h"
#include "cartpole_qlearning/q_learning_agent.h"

#include <cstdint>
#include <deque>
#include <string>

namespace cartpole_qlearning
{
struct EpisodeSummary
{
  std::uint64_t episode = 0;  // 1-based count of episodes this session has ended
  unsigned steps = 0;
  double episode_return = 0.0;
  double mean_return_window = 0.0;  // over the last solved_window episodes (fewer at the start)
  double epsilon = 0.0;
  double alpha = 0.0;
  bool terminated = false;
  bool truncated = false;
  bool solved = false;  // a full window whose mean return reaches solved_mean_return
  std::uint64_t total_steps = 0;
};

struct Decision
{
  StepOutcome outcome;  // the task's verdict on the step that led to the observed state
  bool episode_over = false;
  std::size_t action = 0;  // the next action, when the episode goes on
  double effort = 0.0;     // its effort [N]
};

// The progress line train_headless and the controller print every few episodes.
std::string progressLine(const EpisodeSummary& summary, unsigned window, double steps_per_second, double elapsed_s);

class TrainingSession
{
public:
  // learning = false: greedy actions, no updates, no exploration draws (evaluation).
  TrainingSession(const TaskParams& task, const AgentParams& agent, std::uint64_t seed, bool learning = true);

  // The first state of an episode; returns the first action's effort.
  double beginEpisode(const CartPoleState& start_state);

  // The state the last action led to: learns from the transition and decides what comes next.
  Decision observe(const CartPoleState& state);

  bool inEpisode() const
  {
    return in_episode_;
  }
  // False: evaluation (greedy, no updates).
  bool learning() const
  {
    return learning_;
  }
  // Abandons the running episode without learning from its unfinished end (e.g. an external reset).
  void abortEpisode()
  {
    in_episode_ = false;
  }

  // Valid once an episode has ended.
  const EpisodeSummary& lastEpisode() const
  {
    return last_;
  }
  std::uint64_t episodesEnded() const
  {
    return last_.episode;
  }

  const CartPoleTask& task() const
  {
    return task_;
  }
  const QLearningAgent& agent() const
  {
    return agent_;
  }

  // The table with its training counters brought up to date.
  const QTable& table() const
  {
    return agent_.table();
  }
  // Installs a loaded table (checked against this agent's shape; on a mismatch returns what
  // differs and changes nothing). The schedules resume from the table's episode count.
  std::string replaceTable(QTable table);

private:
  std::size_t chooseAction(std::size_t state);

  CartPoleTask task_;
  QLearningAgent agent_;
  bool learning_;

  bool in_episode_ = false;
  std::size_t state_ = 0;
  std::size_t action_ = 0;
  unsigned steps_ = 0;
  double return_ = 0.0;
  double epsilon_ = 0.0;
  double alpha_ = 0.0;

  std::deque<double> window_;
  double window_sum_ = 0.0;
  EpisodeSummary last_;
};

}  // namespace cartpole_qlearning
