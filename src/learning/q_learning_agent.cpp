#include "cartpole_qlearning/learning/q_learning_agent.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
ScheduleParams AgentParams::defaultEpsilon()
{
  ScheduleParams schedule;
  schedule.type = ScheduleType::Linear;
  schedule.start = 1.0;
  schedule.min = 0.03;
  schedule.decay_episodes = 150.0;
  schedule.log_divisor = 25.0;
  return schedule;
}

ScheduleParams AgentParams::defaultAlpha()
{
  ScheduleParams schedule;
  schedule.type = ScheduleType::Log;
  schedule.start = 1.0;
  schedule.min = 0.05;
  schedule.log_divisor = 15.0;
  return schedule;
}

namespace
{
// Names must tell the rows apart in the trace and in a replay file, each on one line.
std::string stateNamesError(const std::vector<std::string>& names, const DiscretiserParams& discretiser)
{
  if (names.empty())
    return "";
  std::size_t states = 1;
  for (const unsigned b : discretiser.bins)
    states *= b;
  std::ostringstream out;
  if (names.size() != states + 1)
  {
    out << "state_names lists " << names.size() << " names, which is not allowed (must be " << states + 1
        << ": one per table row (the bins give " << states << "), then the terminal state's)";
    return out.str();
  }
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    const std::string& name = names[i];
    if (name.empty() || name.find_first_of("\n\r\t") != std::string::npos || name.front() == ' ' || name.back() == ' ')
    {
      out << "state_names[" << i << "] = '" << name
          << "' is not allowed (must be a non-empty name on one line, without leading or trailing spaces)";
      return out.str();
    }
    for (std::size_t j = 0; j < i; ++j)
    {
      if (names[j] == name)
      {
        out << "state_names[" << i << "] = '" << name << "' is not allowed (state_names[" << j
            << "] has that name already)";
        return out.str();
      }
    }
  }
  return "";
}
}  // namespace

FeatureParams AgentParams::featureParams() const
{
  FeatureParams params;
  params.kind = features;
  params.discretiser = discretiser;
  params.tilings = tilings;
  params.tiles = tiles;
  params.second_tiles = second_tiles;
  params.energy_tiles = energy_tiles;
  params.pole_frequency = pole_frequency;
  params.previous_action = previous_action;
  params.warp = warp;
  params.mirror = mirror;
  return params;
}

std::string AgentParams::validate() const
{
  std::ostringstream out;
  std::string error = featureParams().validate();
  if (!error.empty())
    return error;
  if (actions.empty())
    return "actions = [] is not allowed (must list at least one effort)";
  if (actions.size() > kMaxActions)
    return "actions lists " + std::to_string(actions.size()) + " efforts, which is not allowed (at most " +
           std::to_string(kMaxActions) + ")";
  const std::uint64_t rows = featureParams().rowCount(actions.size());
  if (rows * actions.size() > kMaxTableValues)
    return "a table of " + std::to_string(rows) + " rows of " + std::to_string(actions.size()) +
           " actions is not allowed (more than the " + std::to_string(kMaxTableValues) + " values a table may hold)";
  for (std::size_t i = 0; i < actions.size(); ++i)
  {
    if (!std::isfinite(actions[i]))
    {
      out << "actions[" << i << "] = " << actions[i] << " is not allowed (must be finite)";
      return out.str();
    }
    if (mirror && actions[i] != -actions[actions.size() - 1 - i])
    {
      out << "mirror with actions[" << i << "] = " << actions[i] << " and actions[" << actions.size() - 1 - i
          << "] = " << actions[actions.size() - 1 - i]
          << " is not allowed (a mirrored state's actions are its own in reverse: they must be symmetric, "
             "actions[i] = -actions[n - 1 - i])";
      return out.str();
    }
  }
  if (!(gamma >= 0.0 && gamma <= 1.0))
  {
    out << "gamma = " << gamma << " is not allowed (must be in [0, 1])";
    return out.str();
  }
  if (!(lambda >= 0.0 && lambda <= 1.0))
  {
    out << "lambda = " << lambda << " is not allowed (must be in [0, 1])";
    return out.str();
  }
  if (!std::isfinite(initial_value))
  {
    out << "initial_value = " << initial_value << " is not allowed (must be finite)";
    return out.str();
  }
  if (replay_updates > kMaxReplayUpdates)
  {
    out << "replay_updates = " << replay_updates << " is not allowed (must be in [0, " << kMaxReplayUpdates << "])";
    return out.str();
  }
  if (replay_capacity < 1 || replay_capacity > kMaxReplayCapacity)
  {
    out << "replay_capacity = " << replay_capacity << " is not allowed (must be in [1, " << kMaxReplayCapacity << "])";
    return out.str();
  }
  if (!(replay_alpha >= 0.0 && replay_alpha <= 1.0))
  {
    out << "replay_alpha = " << replay_alpha << " is not allowed (must be in [0, 1])";
    return out.str();
  }
  if (ensemble < 1 || ensemble > kMaxEnsemble)
  {
    out << "ensemble = " << ensemble << " is not allowed (must be in [1, " << kMaxEnsemble << "])";
    return out.str();
  }
  // Learning side by side, the agent holds the ensemble's tables and their mean: together no more
  // than the values one table may hold (kMaxTableValues, 160 MB of doubles).
  const std::uint64_t tables_held = ensemble > 1 ? ensemble + 1u : 1u;
  if (tables_held > 1 && tables_held * rows * actions.size() > kMaxTableValues)
  {
    out << "ensemble = " << ensemble << " with a table of " << rows << " rows of " << actions.size()
        << " actions is not allowed (its " << tables_held << " tables, each and their mean, would hold more than the "
        << kMaxTableValues << " values a table may hold: fewer tables or fewer bins)";
    return out.str();
  }
  if (decision_steps < 1 || decision_steps > kMaxDecisionSteps)
  {
    out << "decision_steps = " << decision_steps << " is not allowed (must be in [1, " << kMaxDecisionSteps << "])";
    return out.str();
  }
  // Names label table rows, one per state: tiles have no such rows.
  error = features == FeatureKind::Tiles && !state_names.empty()
              ? "state_names is not allowed with features tiles (it names the rows of bins, one per state)"
          : previous_action && !state_names.empty()
              ? "state_names is not allowed with previous_action (the rows repeat per previous action)"
              : stateNamesError(state_names, discretiser);
  if (!error.empty())
    return error;
  error = epsilon.validate();
  if (!error.empty())
    return "epsilon/" + error;
  error = alpha.validate();
  if (!error.empty())
    return "alpha/" + error;
  return "";
}

namespace
{
const AgentParams& checked(const AgentParams& params)
{
  const std::string error = params.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
  return params;
}
}  // namespace

QLearningAgent::QLearningAgent(const AgentParams& params, std::uint64_t seed)
  : params_(checked(params)),
    features_(params.featureParams(), params.actions.size()),
    epsilon_(params.epsilon),
    alpha_(params.alpha),
    table_(params.featureParams(), params.actions),
    rng_(seed, kAgentStream)
{
  if (params_.initial_value != 0.0)
  {
    const double weight = params_.initial_value / params_.featureParams().activeRowCount();
    for (std::size_t row = 0; row < table_.stateCount(); ++row)
      for (std::size_t a = 0; a < table_.actionCount(); ++a)
        table_.at(row, a) = weight;
  }
  if (params_.ensemble > 1)
    members_.assign(params_.ensemble, table_);
}

double QLearningAgent::value(const QTable& table, const ActiveRows& state, std::size_t action)
{
  action = state.column(action, table.actionCount());
  double q = table.at(state.rows[0], action);
  for (unsigned i = 1; i < state.count; ++i)
    q += table.at(state.rows[i], action);
  return q;
}

void QLearningAgent::addToWeight(std::size_t row, std::size_t column, double delta)
{
  if (members_.empty())
  {
    table_.at(row, column) += delta;
    return;
  }
  members_[learner_].at(row, column) += delta;
  table_.at(row, column) += delta / static_cast<double>(members_.size());
}

std::size_t QLearningAgent::bestAction(const QTable& table, const ActiveRows& state, double* best_q)
{
  const std::size_t actions = table.actionCount();
  const double* const values = table.values().data();
  if (actions == 2)
  {
    // Two actions (every shipped configuration): the sums in the same order as below, held in
    // registers (the general loop copied the first row through memcpy and kept q in memory: a
    // quarter of a suite step, perf).
    const double* row = values + state.rows[0] * std::size_t{2};
    double q0 = row[0];
    double q1 = row[1];
    for (unsigned i = 1; i < state.count; ++i)
    {
      row = values + state.rows[i] * std::size_t{2};
      q0 += row[0];
      q1 += row[1];
    }
    if (best_q != nullptr)
      *best_q = q1 > q0 ? q1 : q0;
    return q1 > q0 ? 1 : 0;
  }
  // Row by row, all actions at once: each row's weights are contiguous.
  std::array<double, kMaxActions> q;
  const double* first = values + state.rows[0] * actions;
  std::copy(first, first + actions, q.begin());
  for (unsigned i = 1; i < state.count; ++i)
  {
    const double* row = values + state.rows[i] * actions;
    for (std::size_t a = 0; a < actions; ++a)
      q[a] += row[a];
  }
  std::size_t best = 0;
  for (std::size_t a = 1; a < actions; ++a)
  {
    if (q[a] > q[best])
      best = a;
  }
  if (best_q != nullptr)
    *best_q = q[best];
  return best;
}

double QLearningAgent::maxValue(const QTable& table, const ActiveRows& state)
{
  if (state.count == 1)
    return table.max(state.rows[0]);
  double best_q = 0.0;
  bestAction(table, state, &best_q);
  return best_q;
}

std::size_t QLearningAgent::selectAction(const ActiveRows& state, double epsilon, bool* explored)
{
  if (explored != nullptr)
    *explored = false;
  const QTable& values = learner();
  if (rng_.uniform01() < epsilon)
  {
    const auto action = static_cast<std::size_t>(rng_.uniformIndex(values.actionCount()));
    if (explored != nullptr)
      *explored = action != greedyAction(values, state);
    return action;
  }
  return greedyAction(values, state);
}

QUpdate QLearningAgent::update(const ActiveRows& state, std::size_t action, double reward, const ActiveRows& next_state,
                               bool next_is_terminal, double alpha, EligibilityTraces* traces)
{
  // With an ensemble, each of its tables learns on its own values (the target too); the mean
  // follows each change by its share.
  QTable& table = learner();
  QUpdate done;
  done.next_max = next_is_terminal ? 0.0 : maxValue(table, next_state);
  done.target = next_is_terminal ? reward : reward + params_.gamma * done.next_max;
  if (traces != nullptr && params_.lambda > 0.0)
  {
    done.old_value = value(table, state, action);
    traces->visit(state, state.column(action, table.actionCount()), table.actionCount(), table.values().size());
    const double step = alpha / state.count * (done.target - done.old_value);
    const std::vector<std::uint32_t>& indices = traces->indices();
    const std::vector<double>& weights = traces->traces();
    for (std::size_t i = 0; i < indices.size(); ++i)
      addToWeight(indices[i] / table.actionCount(), indices[i] % table.actionCount(), step * weights[i]);
    done.new_value = value(table, state, action);
    if (next_is_terminal)
      traces->clear();
    else
      traces->decay(params_.gamma * params_.lambda);
    return done;
  }
  if (state.count == 1)
  {
    // Bins: one row, the arithmetic in the order it always had (a seed's table stays the same).
    const std::size_t column = state.column(action, table.actionCount());
    double& q = table.at(state.rows[0], column);
    done.old_value = q;
    if (members_.empty())
      q += alpha * (done.target - q);
    else
      addToWeight(state.rows[0], column, alpha * (done.target - q));
    done.new_value = q;
    return done;
  }
  done.old_value = value(table, state, action);
  const double step = alpha / state.count * (done.target - done.old_value);
  const std::size_t column = state.column(action, table.actionCount());
  for (unsigned i = 0; i < state.count; ++i)
    addToWeight(state.rows[i], column, step);
  done.new_value = value(table, state, action);
  return done;
}

std::string QLearningAgent::setLearning(double gamma, const ScheduleParams& epsilon, const ScheduleParams& alpha)
{
  AgentParams candidate = params_;
  candidate.gamma = gamma;
  candidate.epsilon = epsilon;
  candidate.alpha = alpha;
  const std::string error = candidate.validate();
  if (!error.empty())
    return error;
  params_ = std::move(candidate);
  epsilon_ = Schedule(epsilon);
  alpha_ = Schedule(alpha);
  return "";
}

std::string QLearningAgent::replaceTable(QTable table)
{
  const std::string mismatch = table_.shapeMismatch(table);
  if (mismatch.empty())
  {
    table_ = std::move(table);
    for (QTable& member : members_)
      member = table_;
  }
  return mismatch;
}

}  // namespace cartpole_qlearning
