// What the controller does with each state it receives: judge the last step with the task,
// learn from it, choose the next action, and keep the episode statistics. The controller node
// and the headless trainer both drive this class, so they learn identically.
//
// Several robots may feed one session: each has an episode of its own (the state and action
// it left off at, its step count and return), and all share the learner (one Q-table, one
// exploration stream, one count of episodes for the schedules, one solved window over every
// episode in the order they end). The order of the calls across robots is then part of the
// result: the same seed gives the same table only for the same order (a lockstep round answers
// the robots in index order).
#pragma once

#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/learning_settings.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/learning/experience_replay.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/learning/trace.h"

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
struct EpisodeSummary
{
  std::uint64_t episode = 0;  // 1-based count of episodes this session has ended (all robots)
  unsigned steps = 0;
  double episode_return = 0.0;
  double mean_return_window = 0.0;  // over the last solved_window episodes (fewer at the start)
  double epsilon = 0.0;
  double alpha = 0.0;
  double gamma = 0.0;  // the discount in force when the episode ended (live tuning may change it)
  bool terminated = false;
  bool truncated = false;
  bool solved = false;  // a full window whose mean return reaches solved_mean_return
  std::uint64_t total_steps = 0;
  std::size_t robot = 0;                  // the robot whose episode this was
  std::uint64_t robot_episode = 0;        // 1-based count of that robot's episodes
  double robot_mean_return_window = 0.0;  // over that robot's last solved_window episodes
  std::uint64_t robot_total_steps = 0;    // that robot's steps over all its episodes
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

// The mean of the last `size` returns.
class ReturnWindow
{
public:
  explicit ReturnWindow(unsigned size) : size_(size) {}
  void push(double value);
  double mean() const
  {
    return values_.empty() ? 0.0 : sum_ / static_cast<double>(values_.size());
  }
  bool full() const
  {
    return values_.size() == size_;
  }
  // Oldest first.
  std::vector<double> values() const
  {
    return {values_.begin(), values_.end()};
  }

private:
  unsigned size_;
  std::deque<double> values_;
  double sum_ = 0.0;
};

class TrainingSession
{
public:
  // learning = false: greedy actions, no updates, no exploration draws (evaluation).
  // robots: how many robots feed this session (each call names its robot, 0-based).
  TrainingSession(const TaskParams& task, const AgentParams& agent, std::uint64_t seed, bool learning = true,
                  std::size_t robots = 1);

  // The first state of an episode; returns the first action's effort.
  double beginEpisode(const CartPoleState& start_state, std::size_t robot = 0);

  // The state the last action led to: learns from the transition and decides what comes next.
  Decision observe(const CartPoleState& state, std::size_t robot = 0);

  bool inEpisode(std::size_t robot = 0) const
  {
    return episodes_.at(robot).running;
  }
  // Abandons the running episode without learning from its unfinished end (e.g. an external reset).
  void abortEpisode(std::size_t robot = 0)
  {
    episodes_.at(robot).running = false;
  }
  // False: evaluation (greedy, no updates).
  bool learning() const
  {
    return learning_;
  }
  std::size_t robots() const
  {
    return episodes_.size();
  }

  // Called with every update while learning (robot: whose step it was); empty: no trace.
  using TraceSink = std::function<void(std::size_t robot, const TraceStep& step)>;
  void setTrace(TraceSink sink)
  {
    trace_ = std::move(sink);
  }

  // Valid once an episode has ended: the last one, of whichever robot.
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

  // The learning settings in use: at first the configuration's, no override.
  const LearningSettings& learningSettings() const
  {
    return learning_settings_;
  }
  // Live tuning: checks the settings (LearningSettings::validate); on a bad value returns the
  // message and changes nothing. Else they apply at once: gamma from the next update, epsilon
  // and alpha (fixed for an episode when it begins) from the next episode that begins, each
  // schedule read at the table's episode count (it resumes there, it does not start over).
  std::string setLearning(const LearningSettings& settings);

  // The table with its training counters brought up to date.
  const QTable& table() const
  {
    return agent_.table();
  }
  // An ensemble's tables (AgentParams::ensemble > 1; empty otherwise): table() is their mean.
  const std::vector<QTable>& ensembleTables() const
  {
    return agent_.ensembleTables();
  }
  // What a table this session trains says of how to run it (q_table.h): the step it learns and
  // the configuration (training_config.h's trainingConfigText). Put on the table in use now and,
  // while learning, on every table installed later (a table trained further is this
  // configuration's); an evaluation keeps an installed table's own, as it learnt nothing.
  void stampTables(double tau, const std::string& trained_with);
  // Installs a loaded table (checked against this agent's shape, and against the stamped step
  // when both say one; on a mismatch returns what differs and changes nothing). The schedules
  // resume from the table's episode count.
  std::string replaceTable(QTable table);
  // Continues a run from its checkpoint: the table (checked as replaceTable does; on a mismatch
  // returns what differs and changes nothing), the session's episode and step counts from the
  // table's, and the solved window from the returns the checkpoint recorded (oldest first). An
  // episode under way (a table loaded through the service mid-episode) goes on; its steps so far
  // are not in the table's count and are left out of the session's total too, so that the total
  // stays the table's.
  std::string resume(QTable table, const std::vector<double>& recent_returns);
  // A greedy session only (evaluate, control): each decision is made for the state `model`
  // predicts for when the command will act on a robot that answers `steps` late (DelayPredictor),
  // from the next decision (an episode under way counts zeros in flight); 0: for the state
  // observed (the default); kDelayFoundFromStates: `steps` found for each robot from its states. Returns what is wrong
  // (a learning session, too many steps) and changes nothing then. The task still judges the observed state.
  std::string predictDelay(const CartPoleParams& model, unsigned steps);
  unsigned predictedDelaySteps() const
  {
    return predictors_.empty() ? 0 : predictors_.front().steps();
  }
  // predictDelay(model, kDelayFoundFromStates): the delay is found from the states of each robot.
  bool findingDelay() const
  {
    return !predictors_.empty() && predictors_.front().finding();
  }
  // The delay found for a robot so far; none before its states tell it (or when not finding).
  std::optional<unsigned> foundDelaySteps(std::size_t robot) const
  {
    return predictors_.empty() ? std::nullopt : predictors_.at(robot).found();
  }

  // The solved window's returns, oldest first: what a checkpoint records for resume().
  std::vector<double> recentReturns() const
  {
    return returns_.values();
  }

private:
  // One robot's episode.
  struct Episode
  {
    explicit Episode(unsigned window) : returns(window) {}
    // The rows of the state the action was taken in, and of the state it led to: two buffers
    // swapped at each step, so that a step copies no rows.
    const ActiveRows& state() const
    {
      return rows[current];
    }
    ActiveRows& next()
    {
      return rows[current ^ 1];
    }
    bool running = false;
    std::uint64_t number = 0;  // as the trace numbers it (TraceStep::episode)
    std::uint64_t begun = 0;   // the session's count of episodes begun before it (an ensemble's turn)
    std::array<ActiveRows, 2> rows{};
    unsigned current = 0;
    std::size_t action = 0;
    // The decision period (AgentParams::decision_steps): the steps the action has been held for
    // and their rewards summed, the transition the next decision learns from.
    unsigned held = 0;
    double held_reward = 0.0;
    EligibilityTraces traces;  // Q(lambda)'s, this episode's
    unsigned steps = 0;
    // Of steps, those taken before a table was loaded mid-episode (resume()): the loaded table's
    // step count does not hold them, so the session's total does not add them either.
    unsigned steps_before_table = 0;
    double episode_return = 0.0;
    double epsilon = 0.0;
    double alpha = 0.0;
    std::uint64_t ended = 0;
    std::uint64_t total_steps = 0;
    ReturnWindow returns;
  };

  // While learning with traces, an exploring choice ends them (Watkins).
  std::size_t chooseAction(const ActiveRows& state, double epsilon, EligibilityTraces& traces);
  // Stores the transition just learnt from and learns again from replay_updates drawn at random
  // (AgentParams::replay_updates), one step each, without traces: a trace belongs to the episode
  // under way, and a drawn transition to some episode before.
  void replayExperience(const ActiveRows& state, std::size_t action, double reward, const ActiveRows& next_state,
                        bool next_is_terminal, double episode_alpha);
  // The state a decision is made for: the observed one, or its prediction (predictDelay).
  CartPoleState decidedFor(const CartPoleState& observed, std::size_t robot) const
  {
    return predictors_.empty() ? observed : predictors_[robot].predict(observed);
  }

  CartPoleTask task_;
  QLearningAgent agent_;
  // While learning with replay_updates > 0; shared by every robot, as the table is. Not part of a
  // checkpoint: a resumed run starts it empty.
  std::optional<ExperienceReplay> replay_;
  std::vector<DelayPredictor> predictors_;  // one per robot; empty: decide for what is observed
  std::uint64_t begun_ = 0;                 // episodes begun, every robot's
  double stamp_tau_ = 0.0;                  // stampTables' (0: none)
  std::string stamp_trained_with_;
  LearningSettings learning_settings_;
  bool learning_;
  std::vector<Episode> episodes_;
  ReturnWindow returns_;  // every robot's episodes
  EpisodeSummary last_;
  TraceSink trace_;
};

}  // namespace cartpole_qlearning
