// Q-learning with epsilon-greedy exploration over a fixed set of efforts, on bins (tabular) or
// tiles (linear in the tiles' weights). A state is given as the rows it activates (ActiveRows);
// Q(s, a) is the sum of their weights for a, one row for bins.
#pragma once

#include "cartpole_qlearning/learning/discretiser.h"
#include "cartpole_qlearning/learning/eligibility_traces.h"
#include "cartpole_qlearning/learning/features.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/common/random.h"
#include "cartpole_qlearning/learning/schedule.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The longest decision period a config may ask for: a second of the Suite's 0.01 s steps.
constexpr unsigned kMaxDecisionSteps = 100;
// The most tables an ensemble may learn side by side (AgentParams::ensemble).
constexpr unsigned kMaxEnsemble = 16;
// Experience replay's limits: a thousand replayed updates a decision, ten million transitions kept
// (about 5 GB when a state activates 64 rows: the limit of a machine, not of a sensible config).
constexpr unsigned kMaxReplayUpdates = 1000;
constexpr unsigned kMaxReplayCapacity = 10000000;

struct AgentParams
{
  // What the learner sees of the state (features.h). The bins are used by bins only, the bounds
  // by both, tilings and tiles (per dimension) by tiles only.
  FeatureKind features = FeatureKind::Bins;
  DiscretiserParams discretiser;
  unsigned tilings = 8;
  std::array<unsigned, kStateDimensions> tiles{{1, 1, 6, 12}};
  std::array<unsigned, kStateDimensions> second_tiles{{0, 0, 0, 0}};  // FeatureParams::second_tiles
  std::array<unsigned, kStateDimensions> energy_tiles{{0, 0, 0, 0}};  // FeatureParams::energy_tiles
  double pole_frequency = FeatureParams().pole_frequency;             // [rad/s] FeatureParams::pole_frequency
  bool previous_action = false;  // the action taken last is part of what the learner sees
  std::array<double, kStateDimensions> warp{{1.0, 1.0, 1.0, 1.0}};  // FeatureParams::warp
  bool mirror = false;                                              // FeatureParams::mirror
  std::vector<double> actions{-10.0, 10.0};                         // [N] the effort of each action
  double gamma = 0.99;                                              // discount per decision, in [0, 1]
  // Watkins's Q(lambda) (eligibility_traces.h): in [0, 1]; 0 is one-step Q-learning, no traces.
  double lambda = 0.0;
  // Physics steps an action is held for (a decision period): the rewards of its steps summed
  // into one transition, gamma applied once a decision. 1 decides every step.
  unsigned decision_steps = 1;
  // Q(s, a) of every state and action before any learning (each of N active rows' weights holds
  // 1/N of it). Above the returns a task can give, it is optimism: every untried action looks
  // better than what has been tried, and the table explores by itself. 0: today's empty table.
  double initial_value = 0.0;
  // Experience replay (experience_replay.h): after each decision's own update, this many one-step
  // updates from transitions drawn at random among the last replay_capacity ones; 0: none. They take
  // no environment step, so the step counts are those without replay.
  unsigned replay_updates = 0;
  unsigned replay_capacity = 100000;
  // The learning rate of a replayed update; 0: the episode's alpha (the schedule's).
  double replay_alpha = 0.0;
  // Tables learnt side by side (1: one table, as always). Each learns from its own share of the
  // episodes (episode n trains table n mod ensemble) and explores on its own values; the table
  // the agent gives (table(): judged, saved, run greedily) is their mean, kept as they learn. Two
  // tables trained apart err in different states, and their mean holds where either alone fails:
  // robust.yaml's tables, two averaged, held five-minute all_at_once 96-100 of 100 where each
  // alone held 86-98 (docs/notes/tuning.md, "Two tables averaged").
  unsigned ensemble = 1;
  ScheduleParams epsilon = defaultEpsilon();  // exploration rate per episode
  ScheduleParams alpha = defaultAlpha();      // learning rate per episode
  // Names of the table's rows for the trace, then the name of the terminal state (which has no
  // row: its Q is 0); empty: S0 ... S<n-1> and "fallen". Display only: not part of the table.
  std::vector<std::string> state_names;

  // The defaults of config/cartpole.yaml (why: its comments): epsilon linear from 1.0 to 0.03
  // over 150 episodes, alpha on the log schedule from 1.0 to 0.05 over ~150.
  static ScheduleParams defaultEpsilon();
  static ScheduleParams defaultAlpha();

  FeatureParams featureParams() const;

  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
};

// What one update did, in the tutorial's terms: Q(s,a) went from old_value to
// new_value = old_value + alpha * (target - old_value), with target = reward + gamma * next_max
// (next_max = max_a' Q(s',a'), 0 and unused when the next state is terminal).
struct QUpdate
{
  double old_value = 0.0;
  double next_max = 0.0;
  double target = 0.0;
  double new_value = 0.0;
};

class QLearningAgent
{
public:
  // The exploration draws come from the agent's own stream of this seed.
  QLearningAgent(const AgentParams& params, std::uint64_t seed);

  const AgentParams& params() const
  {
    return params_;
  }
  const FeatureMap& features() const
  {
    return features_;
  }
  // Bins only (the default discretiser for tiles).
  const Discretiser& discretiser() const
  {
    return features_.discretiser();
  }
  // The rows a state activates. No allocation.
  // previous: 0 for none (an episode's first state), else 1 + the action taken last.
  void activeRows(const CartPoleState& state, ActiveRows& active, std::size_t previous = 0) const
  {
    features_.activeRows(state, active, previous);
  }
  // The table: with an ensemble, the mean of its tables. Its counters (episodes, steps) and
  // stamps are the run's; its values must not be written here while an ensemble learns (the
  // mean is kept from the tables' updates: replaceTable() sets them all).
  const QTable& table() const
  {
    return table_;
  }
  QTable& table()
  {
    return table_;
  }
  // The tables an ensemble learns (ensemble > 1; empty otherwise), their mean table().
  const std::vector<QTable>& ensembleTables() const
  {
    return members_;
  }
  // Which of the ensemble's tables explores and learns from now on (taken mod ensemble; the one
  // table without an ensemble). TrainingSession gives each episode's number.
  void learnWith(std::uint64_t episode)
  {
    learner_ = members_.empty() ? 0 : static_cast<std::size_t>(episode % members_.size());
  }

  double epsilon(unsigned long episode) const
  {
    return epsilon_.value(episode);
  }
  double alpha(unsigned long episode) const
  {
    return alpha_.value(episode);
  }

  // Replaces the discount and the schedules of a running agent (live tuning), checked as the
  // configuration is (AgentParams::validate); on a bad value returns the message and changes
  // nothing. The schedules are then read at the table's episode count, as if they had applied
  // from the start.
  std::string setLearning(double gamma, const ScheduleParams& epsilon, const ScheduleParams& alpha);

  // Q(s, a): the sum of the active rows' weights for the action, in table() (the mean of an
  // ensemble's tables).
  double value(const ActiveRows& state, std::size_t action) const
  {
    return value(table_, state, action);
  }

  // With probability epsilon a uniformly drawn action, else the greedy one (with an ensemble, on
  // the values of the table learnWith() chose: each explores on its own). Always takes one
  // draw for the coin and, when exploring, one for the action.
  // explored, when given: whether the action taken is not the greedy one (what ends Watkins's
  // traces); a draw that lands on the greedy action is greedy.
  std::size_t selectAction(const ActiveRows& state, double epsilon, bool* explored = nullptr);
  // The first action with the largest Q (ties go to the lowest index, as numpy's argmax).
  std::size_t greedyAction(const ActiveRows& state) const
  {
    return greedyAction(table_, state);
  }
  // The same on any table of this shape: what an evaluation, which learns nothing and so needs no
  // agent, runs (greedy_episodes.cpp).
  static std::size_t greedyAction(const QTable& table, const ActiveRows& state)
  {
    const std::size_t best = state.count == 1 ? table.argmax(state.rows[0]) : bestAction(table, state, nullptr);
    return state.column(best, table.actionCount());
  }
  // The same for a bins state given as its row.
  std::size_t selectAction(std::size_t state, double epsilon)
  {
    return selectAction(ActiveRows::single(state), epsilon);
  }
  std::size_t greedyAction(std::size_t state) const
  {
    return table_.argmax(state);
  }

  // Q(s,a) += alpha * (target - Q(s,a)) with target = reward + gamma * max_a' Q(s',a'); the max
  // term is dropped when next_is_terminal (a fall has no future), kept on truncation. With N
  // active rows each of their weights moves by alpha / N of the error, so Q(s,a) moves by alpha
  // of it whatever N is (alpha keeps its meaning across bins and tilings). Returns what it did
  // (the trace).
  // traces (with lambda > 0): Watkins's Q(lambda); the state's weights for the action are
  // visited, the error moves every traced weight by alpha / N times its trace, and the traces
  // then fade by gamma * lambda (cleared on a terminal state). The caller clears them when it
  // then explores (selectAction's explored) and when an episode begins.
  QUpdate update(const ActiveRows& state, std::size_t action, double reward, const ActiveRows& next_state,
                 bool next_is_terminal, double alpha, EligibilityTraces* traces = nullptr);
  // The same for bins states given as their rows.
  QUpdate update(std::size_t state, std::size_t action, double reward, std::size_t next_state, bool next_is_terminal,
                 double alpha)
  {
    return update(ActiveRows::single(state), action, reward, ActiveRows::single(next_state), next_is_terminal, alpha);
  }

  // Replaces the table after checking it has this agent's features and actions; on a
  // mismatch returns what differs and leaves the table in use as it was. An ensemble's tables
  // all start again from it (a table file holds the mean only).
  std::string replaceTable(QTable table);

private:
  // Over several rows: the greedy action, and its Q in best_q when given.
  static std::size_t bestAction(const QTable& table, const ActiveRows& state, double* best_q);
  static double value(const QTable& table, const ActiveRows& state, std::size_t action);
  static double maxValue(const QTable& table, const ActiveRows& state);
  // The table that explores and learns: the ensemble's table learnWith() chose, else table_.
  QTable& learner()
  {
    return members_.empty() ? table_ : members_[learner_];
  }
  // Adds `delta` to a weight of the learning table and its share to the mean (an ensemble's).
  void addToWeight(std::size_t row, std::size_t column, double delta);

  AgentParams params_;
  FeatureMap features_;
  Schedule epsilon_;
  Schedule alpha_;
  QTable table_;
  std::vector<QTable> members_;  // an ensemble's tables (ensemble > 1), table_ their mean
  std::size_t learner_ = 0;
  RandomStream rng_;
};

}  // namespace cartpole_qlearning
