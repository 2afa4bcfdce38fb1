#include "cartpole_qlearning/cartpole_sim_node.h"

#include "cartpole_qlearning/config.h"
#include "cartpole_qlearning/ros_parameter_source.h"

#include <geometry_msgs/TransformStamped.h>
#include <rosgraph_msgs/Clock.h>

#include <cmath>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
std::string text(double value)
{
  std::ostringstream out;
  out << value;
  return out.str();
}

std::chrono::duration<double> seconds(double s)
{
  return std::chrono::duration<double>(s);
}
}  // namespace

CartPoleSimNode::CartPoleSimNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh)
{
  readParameters();
  simulation_ = std::make_unique<CartPoleSimulation>(physics_, start_state_bound_, seed_);
  noise_ = std::make_unique<RandomStream>(seed_, kNoiseStream);

  joint_state_.name = {"cart_joint", "pole_joint"};
  joint_state_.position.assign(2, 0.0);
  joint_state_.velocity.assign(2, 0.0);
  joint_state_.effort.assign(2, 0.0);

  // A state that reaches no controller (one that subscribes late or restarts) is sent again
  // after lockstep_timeout, unchanged. (Not from a subscriber-connect callback: roscpp runs it
  // some time after the link is up, and in a nodelet manager its copy can overtake or trail the
  // normal one, so a controller would see old states arrive late.)
  joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  if (mode_ == Mode::Lockstep)
    clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
  effort_sub_ = nh_.subscribe("cart_effort", 10, &CartPoleSimNode::onEffort, this, ros::TransportHints().tcpNoDelay());
  reset_srv_ = pnh_.advertiseService("reset", &CartPoleSimNode::onReset, this);

  // The first state: a random start, which takes one tick of sim time like every reset.
  simulation_->resetRandom();
  if (mode_ == Mode::Lockstep)
  {
    sim_time_ = ros::Time(0) + ros::Duration(physics_.tau);
    timer_ = nh_.createSteadyTimer(ros::WallDuration(lockstep_timeout_ / 2), &CartPoleSimNode::onLockstepTimeout, this);
  }
  else
  {
    timer_ = nh_.createSteadyTimer(ros::WallDuration(physics_.tau), &CartPoleSimNode::onRealtimeTick, this);
  }
  publishState();
  ROS_INFO("cartpole_sim: %s mode, tau %g s, integrator %s, seed %llu, start state [%g, %g, %g, %g]",
           mode_ == Mode::Lockstep ? "lockstep" : "realtime", physics_.tau, toString(physics_.integrator).c_str(),
           static_cast<unsigned long long>(seed_), simulation_->state()[0], simulation_->state()[1],
           simulation_->state()[2], simulation_->state()[3]);
}

void CartPoleSimNode::readParameters()
{
  readPhysics(RosParameterSource(nh_), physics_, start_state_bound_);

  const RosParameterSource priv(pnh_);
  const std::string mode = valueOr<std::string>(priv, "mode", "realtime");
  if (mode == "realtime")
    mode_ = Mode::Realtime;
  else if (mode == "lockstep")
    mode_ = Mode::Lockstep;
  else
    refuseParameter(pnh_, "mode", "'" + mode + "'", "allowed: realtime, lockstep");

  const std::int64_t seed = valueOr<std::int64_t>(priv, "seed", 0);
  if (seed < 0)
    refuseParameter(pnh_, "seed", std::to_string(seed), "must be a whole number >= 0");
  seed_ = static_cast<std::uint64_t>(seed);

  const auto positive = [&](const char* name, double& value) {
    value = valueOr(priv, name, value);
    if (!(std::isfinite(value) && value > 0.0))
      refuseParameter(pnh_, name, text(value), "must be finite and > 0");
  };
  const auto non_negative = [&](const char* name, double& value) {
    value = valueOr(priv, name, value);
    if (!(std::isfinite(value) && value >= 0.0))
      refuseParameter(pnh_, name, text(value), "must be finite and >= 0");
  };
  positive("command_timeout", command_timeout_);
  positive("lockstep_timeout", lockstep_timeout_);
  positive("tf_rate", tf_rate_);
  effort_limit_ = physics_.force_mag;
  positive("effort_limit", effort_limit_);
  if (effort_limit_ > physics_.force_mag)
    refuseParameter(pnh_, "effort_limit", text(effort_limit_),
                    "must be <= physics/force_mag = " + text(physics_.force_mag));
  non_negative("position_noise_std", position_noise_std_);
  non_negative("velocity_noise_std", velocity_noise_std_);
  non_negative("effort_noise_std", effort_noise_std_);
  publish_tf_ = valueOr(priv, "publish_tf", publish_tf_);
  world_frame_ = valueOr(priv, "world_frame", world_frame_);
  cart_frame_ = valueOr(priv, "cart_frame", cart_frame_);
  pole_frame_ = valueOr(priv, "pole_frame", pole_frame_);
  for (const std::string* frame : {&world_frame_, &cart_frame_, &pole_frame_})
  {
    if (frame->empty())
      refuseParameter(pnh_,
                      frame == &world_frame_  ? "world_frame"
                      : frame == &cart_frame_ ? "cart_frame"
                                              : "pole_frame",
                      "''", "frame names must not be empty");
  }
}

bool CartPoleSimNode::acceptEffort(double requested, double& effort) const
{
  if (!std::isfinite(requested))
  {
    if (nonfinite_warning_.ready())
      ROS_WARN("cartpole_sim: refused a non-finite effort (%f) on %s", requested, effort_sub_.getTopic().c_str());
    return false;
  }
  effort = std::clamp(requested, -effort_limit_, effort_limit_);
  if (effort != requested && clamp_warning_.ready())
    ROS_WARN("cartpole_sim: effort %g N clamped to the limit of %g N", requested, effort_limit_);
  return true;
}

void CartPoleSimNode::onEffort(const std_msgs::Float64ConstPtr& msg)
{
  double effort = 0.0;
  if (!acceptEffort(msg->data, effort))
    return;
  if (mode_ == Mode::Realtime)
  {
    held_effort_ = effort;
    held_since_ = std::chrono::steady_clock::now();
    have_command_ = true;
    return;
  }
  advance(effort);
}

void CartPoleSimNode::advance(double effort)
{
  double force = effort;
  if (effort_noise_std_ > 0.0)
    force = std::clamp(effort + effort_noise_std_ * noise_->normal(), -effort_limit_, effort_limit_);
  simulation_->step(force);
  if (mode_ == Mode::Lockstep)
    sim_time_ += ros::Duration(physics_.tau);
  publishState();
}

void CartPoleSimNode::onRealtimeTick(const ros::SteadyTimerEvent&)
{
  const bool fresh = have_command_ && std::chrono::steady_clock::now() - held_since_ <= seconds(command_timeout_);
  advance(fresh ? held_effort_ : 0.0);
}

void CartPoleSimNode::onLockstepTimeout(const ros::SteadyTimerEvent&)
{
  if (std::chrono::steady_clock::now() - published_at_ < seconds(lockstep_timeout_))
    return;
  // Late by one tick more: after this process was stalled (a loaded machine), an answer may sit
  // in the queue behind this timer event; it gets its turn before the next tick. Repeating now
  // would draw a second answer, which the next state would take for its own.
  if (!repeat_armed_)
  {
    repeat_armed_ = true;
    return;
  }
  // Unanswered: the state or its answer was lost (a late or restarted controller). Send the
  // same state with the same stamp again; the controller answers it without learning twice.
  ROS_DEBUG("cartpole_sim: no command for %.3f s, publishing the state again", lockstep_timeout_);
  publishState(true);
}

bool CartPoleSimNode::onReset(Reset::Request& request, Reset::Response& response)
{
  if (request.state.empty())
  {
    simulation_->resetRandom();
  }
  else if (request.state.size() == 4)
  {
    for (std::size_t i = 0; i < 4; ++i)
    {
      if (!std::isfinite(request.state[i]))
      {
        response.success = false;
        response.message = "refused: state[" + std::to_string(i) + "] is not finite; the state is unchanged";
        return true;
      }
    }
    simulation_->reset(CartPoleState(request.state[0], request.state[1], request.state[2], request.state[3]));
  }
  else
  {
    response.success = false;
    response.message = "refused: state has " + std::to_string(request.state.size()) +
                       " values; give none (random start) or 4 (x, x_dot, theta, theta_dot)";
    return true;
  }
  // A reset takes one tick of sim time, so the new start state never shares a stamp with the
  // state before it and time never goes backwards.
  if (mode_ == Mode::Lockstep)
    sim_time_ += ros::Duration(physics_.tau);
  const CartPoleState& s = simulation_->state();
  publishState();
  std::ostringstream out;
  out.precision(17);
  out << "reset to [" << s[0] << ", " << s[1] << ", " << s[2] << ", " << s[3] << "]";
  response.success = true;
  response.message = out.str();
  return true;
}

void CartPoleSimNode::publishState(bool repeat)
{
  const auto wall_now = std::chrono::steady_clock::now();
  if (!repeat)
  {
    // A repeat sends this same message again: same stamp, same values, no new noise draws.
    const CartPoleState& s = simulation_->state();
    joint_state_.header.stamp = mode_ == Mode::Lockstep ? sim_time_ : ros::Time::now();
    joint_state_.position[0] = s[0];
    joint_state_.position[1] = s[2];
    joint_state_.velocity[0] = s[1];
    joint_state_.velocity[1] = s[3];
    if (position_noise_std_ > 0.0)
    {
      joint_state_.position[0] += position_noise_std_ * noise_->normal();
      joint_state_.position[1] += position_noise_std_ * noise_->normal();
    }
    if (velocity_noise_std_ > 0.0)
    {
      joint_state_.velocity[0] += velocity_noise_std_ * noise_->normal();
      joint_state_.velocity[1] += velocity_noise_std_ * noise_->normal();
    }
    joint_state_.effort[0] = simulation_->appliedForce();
    joint_state_.effort[1] = 0.0;  // the pole joint is not actuated
  }
  const ros::Time stamp = joint_state_.header.stamp;
  if (mode_ == Mode::Lockstep)
  {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_pub_.publish(clock);
  }
  published_at_ = wall_now;
  repeat_armed_ = false;
  joint_state_pub_.publish(joint_state_);

  if (!publish_tf_ || repeat)  // tf2 refuses a second transform with the same stamp
    return;
  if (mode_ == Mode::Lockstep && wall_now - last_tf_ < seconds(1.0 / tf_rate_))
    return;
  last_tf_ = wall_now;
  const CartPoleState& s = simulation_->state();
  geometry_msgs::TransformStamped cart;
  cart.header.stamp = stamp;
  cart.header.frame_id = world_frame_;
  cart.child_frame_id = cart_frame_;
  cart.transform.translation.x = s[0];
  cart.transform.rotation.w = 1.0;
  geometry_msgs::TransformStamped pole;
  pole.header.stamp = stamp;
  pole.header.frame_id = cart_frame_;
  pole.child_frame_id = pole_frame_;
  // theta about +y: positive theta tips the pole's top toward +x.
  pole.transform.rotation.y = std::sin(s[2] / 2.0);
  pole.transform.rotation.w = std::cos(s[2] / 2.0);
  tf_broadcaster_.sendTransform({cart, pole});
}

}  // namespace cartpole_qlearning
