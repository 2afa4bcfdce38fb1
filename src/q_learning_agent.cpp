#include "cartpole_qlearning/q_learning_agent.h"

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
  schedule.type = ScheduleType::Log;
  schedule.start = 1.0;
  schedule.min = 0.01;
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

FeatureParams AgentParams::featureParams() const
{
  FeatureParams params;
  params.kind = features;
  params.discretiser = discretiser;
  params.tilings = tilings;
  params.tiles = tiles;
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
  for (std::size_t i = 0; i < actions.size(); ++i)
  {
    if (!std::isfinite(actions[i]))
    {
      out << "actions[" << i << "] = " << actions[i] << " is not allowed (must be finite)";
      return out.str();
    }
  }
  if (!(gamma >= 0.0 && gamma <= 1.0))
  {
    out << "gamma = " << gamma << " is not allowed (must be in [0, 1])";
    return out.str();
  }
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
    features_(params.featureParams()),
    epsilon_(params.epsilon),
    alpha_(params.alpha),
    table_(params.featureParams(), params.actions),
    rng_(seed, kAgentStream)
{
}

double QLearningAgent::value(const ActiveRows& state, std::size_t action) const
{
  double q = table_.at(state.rows[0], action);
  for (unsigned i = 1; i < state.count; ++i)
    q += table_.at(state.rows[i], action);
  return q;
}

std::size_t QLearningAgent::greedyAction(const ActiveRows& state, double* best_q) const
{
  const std::size_t actions = table_.actionCount();
  // Row by row, all actions at once: each row's weights are contiguous.
  std::array<double, kMaxActions> q;
  const double* const values = table_.values().data();
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

std::size_t QLearningAgent::greedyAction(const ActiveRows& state) const
{
  if (state.count == 1)
    return table_.argmax(state.rows[0]);
  return greedyAction(state, nullptr);
}

double QLearningAgent::maxValue(const ActiveRows& state) const
{
  if (state.count == 1)
    return table_.max(state.rows[0]);
  double best_q = 0.0;
  greedyAction(state, &best_q);
  return best_q;
}

std::size_t QLearningAgent::selectAction(const ActiveRows& state, double epsilon)
{
  if (rng_.uniform01() < epsilon)
    return static_cast<std::size_t>(rng_.uniformIndex(table_.actionCount()));
  return greedyAction(state);
}

QLearningAgent::Update QLearningAgent::update(const ActiveRows& state, std::size_t action, double reward,
                                              const ActiveRows& next_state, bool next_is_terminal, double alpha)
{
  Update report;
  const double future = next_is_terminal ? 0.0 : params_.gamma * maxValue(next_state);
  report.target = reward + future;
  if (state.count == 1)
  {
    double& q = table_.at(state.rows[0], action);
    report.old_q = q;
    q += alpha * (reward + future - q);
    report.new_q = q;
    return report;
  }
  report.old_q = value(state, action);
  const double step = alpha / state.count * (report.target - report.old_q);
  for (unsigned i = 0; i < state.count; ++i)
    table_.at(state.rows[i], action) += step;
  report.new_q = value(state, action);
  return report;
}

std::string QLearningAgent::replaceTable(QTable table)
{
  const std::string mismatch = table_.shapeMismatch(table);
  if (mismatch.empty())
    table_ = std::move(table);
  return mismatch;
}

}  // namespace cartpole_qlearning
