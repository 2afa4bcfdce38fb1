// The task: where an episode starts, when it ends and what each step is worth, for each kind
// (CartPole-v1's balance, or one of DeepMind Control Suite's cart-pole tasks). The controller
// decides this from the state it receives; the simulator is only physics, like a robot.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <optional>
#include <string>

namespace cartpole_qlearning
{
enum class RewardScheme
{
  Gymnasium,      // +1 every step, the terminating one included (CartPole-v1)
  Seed,           // +1 while alive, -1 on the step that falls (the Q-learning tutorial's)
  SuttonBarto,    // 0 while alive, -1 on the step that falls (Barto, Sutton and Anderson 1983)
  Alive,          // +1 while alive, 0 on the step that falls (Gymnasium's InvertedPendulum-v5)
  Centred,        // sutton_barto, and while alive -kCentredCost x (x / x_threshold)^2: a cart that drifts
                  // towards the end of the track costs before it falls (minutes-long control)
  AliveQuadratic  // alive, less TaskParams::x_cost x^2 + x_dot_cost x_dot^2 a step: a cart that drifts or
                  // runs costs long before the track's end does (a shaped training reward)
};

// Which task (task/kind). The Control Suite's kinds (suite/cartpole.py's Balance task) never end on
// the angle or the cart, last 1,000 steps of 0.01 s, and score each step in [0, 1] by their own
// reward (task/reward is CartPole-v1's alone).
enum class TaskKind
{
  CartPoleV1,    // Gymnasium's CartPole-v1: starts near upright, ends past 12 degrees or 2.4 m (the default)
  Balance,       // the Suite's balance: starts near upright, the smooth reward
  Swingup,       // the Suite's swingup: starts hanging, the smooth reward
  SwingupSparse  // the Suite's swingup_sparse: starts hanging, 1 when upright and centred, else 0
};

// Parses "cartpole_v1", "balance", "swingup" or "swingup_sparse"; throws std::invalid_argument otherwise.
TaskKind taskKindFromString(const std::string& name);
std::string toString(TaskKind kind);
inline bool isSuiteTask(TaskKind kind)
{
  return kind != TaskKind::CartPoleV1;
}

// The Suite's episode (10 s of 0.01 s steps) and its motor: ctrl in [-1, 1] times gear 10, so that an
// effort of F newtons is the control F / 10 its reward charges for.
constexpr unsigned kSuiteEpisodeSteps = 1000;
constexpr double kSuiteTau = 0.01;
constexpr double kSuiteEffortPerControl = 10.0;

// The Suite's reward for the state after a step and the control of that step (the effort / 10 N):
// smooth = upright x small control x small velocity x centred, each a factor of
// utils/rewards.py's tolerance; sparse = 1 when |x| <= 0.25 and cos(theta) >= 0.995, else 0.
double suiteSmoothReward(const CartPoleState& state, double control);
double suiteSparseReward(const CartPoleState& state);

// What a step at the end of the track costs under RewardScheme::Centred, against -1 for the fall.
constexpr double kCentredCost = 0.01;

// Parses "gymnasium", "seed", "sutton_barto", "alive", "centred" or "alive_quadratic"; throws
// std::invalid_argument otherwise.
RewardScheme rewardSchemeFromString(const std::string& name);
std::string toString(RewardScheme scheme);
// What a return means under the scheme, for a reader of the logs: "0 a step, -1 on the fall".
std::string rewardMeaning(RewardScheme scheme);

struct TaskParams
{
  TaskKind kind = TaskKind::CartPoleV1;           // the Suite's kinds read none of the CartPole-v1 keys below
  double x_threshold = 2.4;                       // [m] terminated when |x| > this
  double theta_threshold_deg = 12.0;              // [deg] terminated when |theta| > this
  unsigned max_episode_steps = 500;               // truncated after this many steps
  RewardScheme reward = RewardScheme::Gymnasium;  // what the learner trains on
  // The reward whose returns the solved window averages (and episodes report); none: `reward`'s. A
  // shaped training reward is then judged by the task's own (e.g. InvertedPendulum-v5's steps alive).
  std::optional<RewardScheme> solved_reward;
  double x_cost = 0.0;                // [1/m^2] alive_quadratic's cost of x^2 a step
  double x_dot_cost = 0.0;            // [s^2/m^2] alive_quadratic's cost of x_dot^2 a step
  double solved_mean_return = 475.0;  // solved when the mean return of the last window episodes >= this
  unsigned solved_window = 100;       // episodes in that window

  // The threshold in radians, computed the way Gymnasium does (12 * 2 * pi / 360).
  double thetaThresholdRad() const;
  // The reward the solved window judges: solved_reward, else reward.
  RewardScheme scoreReward() const
  {
    return solved_reward.value_or(reward);
  }
  // The largest return (of scoreReward()) an episode can have (one that balances to max_episode_steps).
  double largestReturn() const;
  // Whether solved_mean_return can be reached at all: not when scored by sutton_barto or centred (at most 0), nor with
  // episodes shorter than it. Training with such a task never says solved; its goal is elsewhere
  // (training/until suite_passes).
  bool solvable() const
  {
    return largestReturn() >= solved_mean_return;
  }
  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
  // Where a random episode starts: CartPole-v1's each value uniform in +-start_state_bound (the
  // physics section's); the Suite's their own (start_state_bound unused).
  StartDistribution start(double start_state_bound) const;
};

struct StepOutcome
{
  double reward = 0.0;      // the training reward (TaskParams::reward)
  double score = 0.0;       // what the step adds to the episode's return (TaskParams::scoreReward())
  bool terminated = false;  // fell: the transition does not bootstrap
  bool truncated = false;   // out of time: the transition bootstraps
  bool done() const
  {
    return terminated || truncated;
  }
};

class CartPoleTask
{
public:
  explicit CartPoleTask(const TaskParams& params = TaskParams());

  const TaskParams& params() const
  {
    return params_;
  }

  // True when the state is outside the thresholds (strict inequalities, as Gymnasium).
  bool isTerminal(const CartPoleState& state) const;

  // Judges the step that produced new_state, the steps_taken-th of its episode (1-based), under the
  // effort [N] commanded for it (the Suite's rewards charge for it).
  // Inline (below) with isTerminal: every step of training and of the suite's verdicts asks.
  StepOutcome evaluate(const CartPoleState& new_state, unsigned steps_taken, double effort) const;

private:
  double rewardOf(RewardScheme scheme, const CartPoleState& new_state, bool terminated) const;
  StepOutcome evaluateSuite(const CartPoleState& new_state, unsigned steps_taken, double effort) const;

  TaskParams params_;
  double theta_threshold_rad_;
};

inline bool CartPoleTask::isTerminal(const CartPoleState& state) const
{
  if (isSuiteTask(params_.kind))
    return false;
  return state[0] < -params_.x_threshold || state[0] > params_.x_threshold || state[2] < -theta_threshold_rad_ ||
         state[2] > theta_threshold_rad_;
}

inline StepOutcome CartPoleTask::evaluate(const CartPoleState& new_state, unsigned steps_taken, double effort) const
{
  if (isSuiteTask(params_.kind))
    return evaluateSuite(new_state, steps_taken, effort);
  StepOutcome outcome;
  outcome.terminated = isTerminal(new_state);
  // A step that both falls and hits the limit counts as a fall: there is no future to bootstrap on.
  outcome.truncated = !outcome.terminated && steps_taken >= params_.max_episode_steps;
  outcome.reward = rewardOf(params_.reward, new_state, outcome.terminated);
  outcome.score =
      params_.solved_reward ? rewardOf(*params_.solved_reward, new_state, outcome.terminated) : outcome.reward;
  return outcome;
}

inline double CartPoleTask::rewardOf(RewardScheme scheme, const CartPoleState& new_state, bool terminated) const
{
  switch (scheme)
  {
    case RewardScheme::Gymnasium:
      return 1.0;
    case RewardScheme::Seed:
      return terminated ? -1.0 : 1.0;
    case RewardScheme::SuttonBarto:
      return terminated ? -1.0 : 0.0;
    case RewardScheme::Alive:
      return terminated ? 0.0 : 1.0;
    case RewardScheme::Centred: {
      const double off_centre = new_state[0] / params_.x_threshold;
      return terminated ? -1.0 : -kCentredCost * off_centre * off_centre;
    }
    case RewardScheme::AliveQuadratic:
      return terminated ? 0.0
                        : 1.0 - params_.x_cost * new_state[0] * new_state[0] -
                              params_.x_dot_cost * new_state[1] * new_state[1];
  }
  return 0.0;
}

}  // namespace cartpole_qlearning
