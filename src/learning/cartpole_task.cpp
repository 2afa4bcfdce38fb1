#include "cartpole_qlearning/learning/cartpole_task.h"

#include <cmath>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
const char* const kTaskKindNames[] = {"cartpole_v1", "balance", "swingup", "swingup_sparse"};
constexpr TaskKind kTaskKinds[] = {TaskKind::CartPoleV1, TaskKind::Balance, TaskKind::Swingup, TaskKind::SwingupSparse};

// utils/rewards.py's tolerance of a value with bounds (0, 0), its gaussian sigmoid and its default
// value_at_margin 0.1: 1 at 0, 0.1 at +-margin, falling as 0.1^((value / margin)^2).
double gaussianNearZero(double value, double margin)
{
  const double scaled = value / margin;
  return std::pow(0.1, scaled * scaled);
}

// tolerance with bounds (0, 0), margin 1, value_at_margin 0 and the quadratic sigmoid: 1 - u^2
// inside +-1, 0 outside.
double quadraticNearZero(double control)
{
  return std::fabs(control) < 1.0 ? 1.0 - control * control : 0.0;
}
}  // namespace

TaskKind taskKindFromString(const std::string& name)
{
  for (std::size_t i = 0; i < std::size(kTaskKinds); ++i)
    if (name == kTaskKindNames[i])
      return kTaskKinds[i];
  throw std::invalid_argument("unknown task kind '" + name +
                              "' (allowed: cartpole_v1, balance, swingup, swingup_sparse)");
}

std::string toString(TaskKind kind)
{
  for (std::size_t i = 0; i < std::size(kTaskKinds); ++i)
    if (kind == kTaskKinds[i])
      return kTaskKindNames[i];
  return "unknown";
}

namespace
{
// cos(theta) of the pole on the circle: a turn further on is the same pole, and the same number
// whether it comes unwrapped (the simulation's state) or wrapped into [-pi, pi] (a controller's
// reading of a robot, robot_interface.h): remainder is exact, so both give cos the same argument and
// a table trained on the graph is train_headless's, bit for bit.
double poleCosine(double theta)
{
  return std::cos(std::fabs(theta) > M_PI ? std::remainder(theta, 2.0 * M_PI) : theta);
}
}  // namespace

double suiteSmoothReward(const CartPoleState& state, double control)
{
  const double upright = (poleCosine(state[2]) + 1.0) / 2.0;
  const double centred = (1.0 + gaussianNearZero(state[0], 2.0)) / 2.0;
  const double small_control = (4.0 + quadraticNearZero(control)) / 5.0;
  const double small_velocity = (1.0 + gaussianNearZero(state[3], 5.0)) / 2.0;
  return upright * small_control * small_velocity * centred;
}

double suiteSparseReward(const CartPoleState& state)
{
  // Both bounds inclusive, as tolerance's with margin 0.
  const bool centred = state[0] >= -0.25 && state[0] <= 0.25;
  const bool upright = poleCosine(state[2]) >= 0.995;
  return centred && upright ? 1.0 : 0.0;
}

RewardScheme rewardSchemeFromString(const std::string& name)
{
  if (name == "gymnasium")
    return RewardScheme::Gymnasium;
  if (name == "seed")
    return RewardScheme::Seed;
  if (name == "sutton_barto")
    return RewardScheme::SuttonBarto;
  if (name == "alive")
    return RewardScheme::Alive;
  if (name == "centred")
    return RewardScheme::Centred;
  if (name == "alive_quadratic")
    return RewardScheme::AliveQuadratic;
  throw std::invalid_argument("unknown reward scheme '" + name +
                              "' (allowed: gymnasium, seed, sutton_barto, alive, centred, alive_quadratic)");
}

std::string toString(RewardScheme scheme)
{
  switch (scheme)
  {
    case RewardScheme::Gymnasium:
      return "gymnasium";
    case RewardScheme::Seed:
      return "seed";
    case RewardScheme::SuttonBarto:
      return "sutton_barto";
    case RewardScheme::Alive:
      return "alive";
    case RewardScheme::Centred:
      return "centred";
    case RewardScheme::AliveQuadratic:
      return "alive_quadratic";
  }
  return "unknown";
}

std::string rewardMeaning(RewardScheme scheme)
{
  switch (scheme)
  {
    case RewardScheme::Gymnasium:
      return "+1 a step";
    case RewardScheme::Seed:
      return "+1 a step, -1 on the fall";
    case RewardScheme::SuttonBarto:
      return "0 a step, -1 on the fall";
    case RewardScheme::Alive:
      return "+1 a step, 0 on the fall";
    case RewardScheme::Centred: {
      std::ostringstream out;
      out << "-" << kCentredCost << " x (x / x_threshold)^2 a step, -1 on the fall";
      return out.str();
    }
    case RewardScheme::AliveQuadratic:
      return "+1 - x_cost x^2 - x_dot_cost x_dot^2 a step, 0 on the fall";
  }
  return "unknown";
}

double TaskParams::largestReturn() const
{
  if (isSuiteTask(kind))
    return static_cast<double>(max_episode_steps);  // at most 1 a step
  const RewardScheme score = scoreReward();
  return score == RewardScheme::SuttonBarto || score == RewardScheme::Centred ? 0.0
                                                                              : static_cast<double>(max_episode_steps);
}

double TaskParams::thetaThresholdRad() const
{
  return theta_threshold_deg * 2.0 * M_PI / 360.0;
}

std::string TaskParams::validate() const
{
  std::ostringstream out;
  if (!(std::isfinite(x_threshold) && x_threshold > 0.0))
    out << "x_threshold = " << x_threshold << " is not allowed (must be finite and > 0)";
  else if (!(std::isfinite(theta_threshold_deg) && theta_threshold_deg > 0.0 && theta_threshold_deg < 90.0))
    out << "theta_threshold_deg = " << theta_threshold_deg << " is not allowed (must be in (0, 90))";
  else if (max_episode_steps == 0)
    out << "max_episode_steps = 0 is not allowed (must be >= 1)";
  else if (!std::isfinite(solved_mean_return))
    out << "solved_mean_return = " << solved_mean_return << " is not allowed (must be finite)";
  else if (solved_window == 0)
    out << "solved_window = 0 is not allowed (must be >= 1)";
  else if (!(std::isfinite(x_cost) && x_cost >= 0.0))
    out << "x_cost = " << x_cost << " is not allowed (must be finite and >= 0)";
  else if (!(std::isfinite(x_dot_cost) && x_dot_cost >= 0.0))
    out << "x_dot_cost = " << x_dot_cost << " is not allowed (must be finite and >= 0)";
  else if (isSuiteTask(kind) && (reward != RewardScheme::Gymnasium || solved_reward))
    out << "reward " << toString(reward) << (solved_reward ? " and solved_reward" : "") << " are not allowed with kind "
        << toString(kind) << " (the kind's own reward scores every step)";
  else if (reward != RewardScheme::AliveQuadratic && (x_cost != 0.0 || x_dot_cost != 0.0))
    out << "x_cost = " << x_cost << " and x_dot_cost = " << x_dot_cost << " are not allowed with reward "
        << toString(reward) << " (only alive_quadratic reads them: must be 0)";
  return out.str();
}

StartDistribution TaskParams::start(double start_state_bound) const
{
  StartDistribution start;
  switch (kind)
  {
    case TaskKind::CartPoleV1:
      return StartDistribution::uniform(start_state_bound);
    case TaskKind::Balance:
      // Cart uniform in +-0.1 m, pole uniform in +-0.034 rad, both velocities 0.01 x normal.
      start.spread << 0.1, 0.01, 0.034, 0.01;
      start.normal = {false, true, false, true};
      return start;
    case TaskKind::Swingup:
    case TaskKind::SwingupSparse:
      // Hanging: theta pi, every value 0.01 x normal about its centre.
      start.centre << 0.0, 0.0, M_PI, 0.0;
      start.spread.fill(0.01);
      start.normal = {true, true, true, true};
      return start;
  }
  return start;
}

StepOutcome CartPoleTask::evaluateSuite(const CartPoleState& new_state, unsigned steps_taken, double effort) const
{
  StepOutcome outcome;
  outcome.truncated = steps_taken >= params_.max_episode_steps;
  outcome.reward = params_.kind == TaskKind::SwingupSparse
                       ? suiteSparseReward(new_state)
                       : suiteSmoothReward(new_state, effort / kSuiteEffortPerControl);
  outcome.score = outcome.reward;
  return outcome;
}

CartPoleTask::CartPoleTask(const TaskParams& params) : params_(params), theta_threshold_rad_(params.thetaThresholdRad())
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
}

}  // namespace cartpole_qlearning
