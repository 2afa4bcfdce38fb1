#include "cartpole_qlearning/learning/cartpole_task.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
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
  else if (reward != RewardScheme::AliveQuadratic && (x_cost != 0.0 || x_dot_cost != 0.0))
    out << "x_cost = " << x_cost << " and x_dot_cost = " << x_dot_cost << " are not allowed with reward "
        << toString(reward) << " (only alive_quadratic reads them: must be 0)";
  return out.str();
}

CartPoleTask::CartPoleTask(const TaskParams& params) : params_(params), theta_threshold_rad_(params.thetaThresholdRad())
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
}

}  // namespace cartpole_qlearning
