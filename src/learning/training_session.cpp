#include "cartpole_qlearning/learning/training_session.h"

#include <cstdio>
#include <sstream>
#include <stdexcept>

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

void ReturnWindow::push(double value)
{
  values_.push_back(value);
  sum_ += value;
  if (values_.size() > size_)
  {
    sum_ -= values_.front();
    values_.pop_front();
  }
}

TrainingSession::TrainingSession(const TaskParams& task, const AgentParams& agent, std::uint64_t seed, bool learning,
                                 std::size_t robots)
  : task_(task),
    agent_(agent, seed),
    learning_settings_(LearningSettings::of(agent)),
    learning_(learning),
    returns_(task.solved_window)
{
  if (robots < 1)
    throw std::invalid_argument("TrainingSession: at least one robot");
  episodes_.assign(robots, Episode(task.solved_window));
  if (learning_ && agent.replay_updates > 0)
    replay_.emplace(agent.replay_capacity, seed);
}

void TrainingSession::replayExperience(const ActiveRows& state, std::size_t action, double reward,
                                       const ActiveRows& next_state, bool next_is_terminal, double episode_alpha)
{
  replay_->add(state, action, reward, next_state, next_is_terminal);
  const double alpha = agent_.params().replay_alpha > 0.0 ? agent_.params().replay_alpha : episode_alpha;
  for (unsigned i = 0; i < agent_.params().replay_updates; ++i)
  {
    const ReplayedTransition& drawn = replay_->draw();
    agent_.update(drawn.state, drawn.action, drawn.reward, drawn.next_state, drawn.next_is_terminal, alpha);
  }
}

std::string TrainingSession::predictDelay(const CartPoleParams& model, unsigned steps)
{
  if (steps == 0)
  {
    predictors_.clear();
    return "";
  }
  if (learning_)
    return "a prediction of the robot's delay is for a greedy table (evaluate, control): training learns from the "
           "states it observes";
  if (steps > kMaxPredictedDelaySteps && steps != kDelayFoundFromStates)
    return "a prediction of " + std::to_string(steps) + " steps is not allowed (must be in [0, " +
           std::to_string(kMaxPredictedDelaySteps) + "])";
  predictors_.assign(episodes_.size(), DelayPredictor(model, steps));
  return "";
}

std::size_t TrainingSession::chooseAction(const ActiveRows& state, double epsilon, EligibilityTraces& traces)
{
  if (!learning_)
    return agent_.greedyAction(state);
  if (agent_.params().lambda <= 0.0)
    return agent_.selectAction(state, epsilon);
  bool explored = false;
  const std::size_t action = agent_.selectAction(state, epsilon, &explored);
  if (explored)
    traces.clear();
  return action;
}

double TrainingSession::beginEpisode(const CartPoleState& start_state, std::size_t robot)
{
  Episode& e = episodes_.at(robot);
  // Schedules count every episode the table has seen, so a loaded table resumes where it was.
  const std::uint64_t episode = agent_.table().episodes;
  e.epsilon = learning_ ? agent_.epsilon(episode) : 0.0;
  e.alpha = learning_ ? agent_.alpha(episode) : 0.0;
  e.running = true;
  e.number = episodes_.size() == 1 ? last_.episode + 1 : e.ended + 1;
  e.steps = 0;
  e.steps_before_table = 0;
  e.episode_return = 0.0;
  e.held = 0;
  e.held_reward = 0.0;
  e.traces.clear();
  // With an ensemble (AgentParams::ensemble), episode n of the session is table n mod ensemble's.
  e.begun = begun_++;
  agent_.learnWith(e.begun);
  if (!predictors_.empty())
    predictors_[robot].begin(start_state);
  agent_.activeRows(decidedFor(start_state, robot), e.rows[e.current]);
  e.action = chooseAction(e.state(), e.epsilon, e.traces);
  const double effort = agent_.table().actions()[e.action];
  if (!predictors_.empty())
    predictors_[robot].sent(effort);
  return effort;
}

Decision TrainingSession::observe(const CartPoleState& state, std::size_t robot)
{
  Episode& e = episodes_.at(robot);
  Decision decision;
  ++e.steps;
  decision.outcome = task_.evaluate(state, e.steps, agent_.table().actions()[e.action]);
  e.episode_return += decision.outcome.score;
  if (!predictors_.empty())
    predictors_[robot].observed(state);
  // Within a decision period the action is held and its rewards summed (one step a decision
  // learns from the step's reward itself, as it always did).
  e.held_reward = e.held == 0 ? decision.outcome.reward : e.held_reward + decision.outcome.reward;
  ++e.held;
  if (!decision.outcome.done() && e.held < agent_.params().decision_steps)
  {
    decision.action = e.action;
    decision.effort = agent_.table().actions()[e.action];
    if (!predictors_.empty())
      predictors_[robot].sent(decision.effort);
    return decision;
  }
  const double reward = e.held_reward;
  const unsigned held = e.held;
  e.held = 0;
  e.held_reward = 0.0;
  // The action just taken: with previous_action, part of what the learner sees of this state.
  // (A predicting session does not learn: its rows are only what the next action is chosen on.)
  agent_.activeRows(decidedFor(state, robot), e.next(), e.action + 1);
  agent_.learnWith(e.begun);  // robots' episodes interleave: this one's table learns and chooses
  if (learning_)
  {
    const QUpdate update = agent_.update(e.state(), e.action, reward, e.next(), decision.outcome.terminated, e.alpha,
                                         agent_.params().lambda > 0.0 ? &e.traces : nullptr);
    agent_.table().steps += held;
    if (replay_)
      replayExperience(e.state(), e.action, reward, e.next(), decision.outcome.terminated, e.alpha);
    if (trace_)
    {
      TraceStep step;
      step.episode = e.number;
      step.step = e.steps;
      // One row per state: the trace is for bins (features tiles refuse it, see traceRefusal).
      step.state = e.state().rows[0];
      step.action = e.action;
      step.reward = reward;
      step.next_state = e.next().rows[0];
      step.terminal = decision.outcome.terminated;
      step.truncated = decision.outcome.truncated;
      step.alpha = e.alpha;
      step.gamma = agent_.params().gamma;
      step.update = update;
      trace_(robot, step);
    }
  }

  if (!decision.outcome.done())
  {
    e.current ^= 1;
    e.action = chooseAction(e.state(), e.epsilon, e.traces);
    decision.action = e.action;
    decision.effort = agent_.table().actions()[e.action];
    if (!predictors_.empty())
      predictors_[robot].sent(decision.effort);
    return decision;
  }

  decision.episode_over = true;
  e.running = false;
  if (learning_)
    ++agent_.table().episodes;
  returns_.push(e.episode_return);
  e.returns.push(e.episode_return);
  ++e.ended;
  e.total_steps += e.steps;

  last_.episode += 1;
  last_.steps = e.steps;
  last_.episode_return = e.episode_return;
  last_.mean_return_window = returns_.mean();
  last_.epsilon = e.epsilon;
  last_.alpha = e.alpha;
  last_.gamma = agent_.params().gamma;
  last_.terminated = decision.outcome.terminated;
  last_.truncated = decision.outcome.truncated;
  last_.solved = returns_.full() && last_.mean_return_window >= task_.params().solved_mean_return;
  last_.total_steps += e.steps - e.steps_before_table;
  last_.robot = robot;
  last_.robot_episode = e.ended;
  last_.robot_mean_return_window = e.returns.mean();
  last_.robot_total_steps = e.total_steps;
  return decision;
}

std::string TrainingSession::setLearning(const LearningSettings& settings)
{
  std::string error = settings.validate();
  if (error.empty())
    error = agent_.setLearning(settings.gamma, settings.effectiveEpsilon(), settings.effectiveAlpha());
  if (error.empty())
    learning_settings_ = settings;
  return error;
}

void TrainingSession::stampTables(double tau, const std::string& trained_with)
{
  stamp_tau_ = tau;
  stamp_trained_with_ = trained_with;
  agent_.table().tau = tau;
  agent_.table().trained_with = trained_with;
}

std::string TrainingSession::replaceTable(QTable table)
{
  // Values learnt at another step answer another question: the shape alone does not show it.
  if (stamp_tau_ > 0.0 && table.tau > 0.0 && table.tau != stamp_tau_)
  {
    std::ostringstream out;
    out << "tau " << table.tau << " differs from " << stamp_tau_;
    return out.str();
  }
  if (learning_ && (stamp_tau_ > 0.0 || !stamp_trained_with_.empty()))
  {
    table.tau = stamp_tau_;
    table.trained_with = stamp_trained_with_;
  }
  return agent_.replaceTable(std::move(table));
}

std::string TrainingSession::resume(QTable table, const std::vector<double>& recent_returns)
{
  const std::uint64_t episodes = table.episodes;
  const std::uint64_t steps = table.steps;
  const std::string mismatch = replaceTable(std::move(table));
  if (!mismatch.empty())
    return mismatch;
  last_ = EpisodeSummary();
  last_.episode = episodes;
  last_.total_steps = steps;
  for (Episode& e : episodes_)
    e.steps_before_table = e.running ? e.steps : 0;
  returns_ = ReturnWindow(task_.params().solved_window);
  for (double value : recent_returns)
    returns_.push(value);
  last_.mean_return_window = returns_.mean();
  return "";
}

}  // namespace cartpole_qlearning
