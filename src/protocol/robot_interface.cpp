#include "cartpole_qlearning/protocol/robot_interface.h"

#include <cmath>

namespace cartpole_qlearning
{
double wrapAngle(double angle)
{
  const double two_pi = 2.0 * M_PI;
  double wrapped = std::fmod(angle, two_pi);  // in (-2 pi, 2 pi)
  if (wrapped > M_PI)
    wrapped -= two_pi;
  else if (wrapped <= -M_PI)
    wrapped += two_pi;
  return wrapped;
}

JointReadings robotReadings(const RobotInterfaceParams& p, const CartPoleState& s, int pole_turns, bool velocities)
{
  JointReadings r;
  r.cart_position = p.cart_sign * s[0] + p.cart_zero;
  r.pole_position = p.pole_angle_sign * s[2] + p.pole_upright + 2.0 * M_PI * pole_turns;
  if (velocities)
  {
    r.cart_velocity = p.cart_sign * s[1];
    r.pole_velocity = p.pole_angle_sign * s[3];
  }
  return r;
}

StateMapping::StateMapping(const RobotInterfaceParams& params) : params_(params) {}

CartPoleState StateMapping::map(Stamp stamp, const JointReadings& r)
{
  const double x = params_.cart_sign * (r.cart_position - params_.cart_zero);
  const double theta = wrapAngle(params_.pole_angle_sign * (r.pole_position - params_.pole_upright));
  if (r.cart_velocity && r.pole_velocity)
  {
    x_dot_ = params_.cart_sign * *r.cart_velocity;
    theta_dot_ = params_.pole_angle_sign * *r.pole_velocity;
  }
  else if (last_stamp_ && stamp > *last_stamp_)
  {
    const double dt = static_cast<double>(stamp - *last_stamp_) * 1e-9;
    const double s = params_.velocity_smoothing;
    x_dot_ = s * x_dot_ + (1.0 - s) * (x - last_x_) / dt;
    theta_dot_ = s * theta_dot_ + (1.0 - s) * wrapAngle(theta - last_theta_) / dt;
  }
  else if (!last_stamp_ || stamp < *last_stamp_)
  {
    x_dot_ = 0.0;  // nothing to difference against: the first state, or time set back
    theta_dot_ = 0.0;
  }
  if (!last_stamp_ || stamp != *last_stamp_)
  {
    last_stamp_ = stamp;
    last_x_ = x;
    last_theta_ = theta;
  }
  return CartPoleState(x, x_dot_, theta, theta_dot_);
}

DecisionClock::DecisionClock(double period_s)
  : period_(period_s > 0.0 ? static_cast<Stamp>(std::llround(period_s * 1e9)) : 0), tolerance_(period_ / 5)
{
}

DecisionClock::Verdict DecisionClock::onState(Stamp stamp)
{
  Verdict verdict;
  if (period_ == 0 || stamp == 0)
    return verdict;
  if (last_ && stamp == *last_)
    return verdict;  // a repeat: the protocol answers it
  if (last_ && stamp > *last_)
  {
    // Decisions keep to a grid of due times a period apart, not to the last state's stamp: a
    // real-time driver's jitter would otherwise make every state that comes a little early miss
    // its decision, and the next one come two periods after the last.
    if (stamp + tolerance_ < due_)
    {
      verdict.decide = false;
      return verdict;
    }
    // The rate, not one gap, is slow or not: a moving mean of the decided states' gaps.
    const double gap = static_cast<double>(stamp - *last_);
    mean_gap_ = mean_gap_ > 0.0 ? 0.9 * mean_gap_ + 0.1 * gap : gap;
    verdict.slow = mean_gap_ > 1.5 * static_cast<double>(period_);
    // Half a period or more behind the grid (a slower driver, a gap, a clock that drifts): the
    // grid starts again here.
    due_ = (stamp < due_ + period_ / 2 ? due_ : stamp) + period_;
  }
  else
  {
    due_ = stamp + period_;  // the first state, or time set back (the protocol judges it)
  }
  last_ = stamp;
  return verdict;
}

SampledPhysics::SampledPhysics(Stamp tau, Stamp period) : tau_(tau), period_(period) {}

void SampledPhysics::restart(Stamp stamp)
{
  next_step_ = stamp;
}

std::uint64_t SampledPhysics::stepsAfter(Stamp stamp)
{
  std::uint64_t steps = 0;
  for (; next_step_ < stamp + period_; next_step_ += tau_)
    ++steps;
  return steps;
}

}  // namespace cartpole_qlearning
