#include "cartpole_qlearning/ros/cartpole_sim.h"

#include "cartpole_qlearning/config.h"
#include "cartpole_qlearning/ros/conversions.h"
#include "cartpole_qlearning/ros/parameter_source.h"

#include <rosgraph_msgs/Clock.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
WallClock::duration wallDuration(double s)
{
  return std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(s));
}

ros::Time toRosTime(Stamp stamp)
{
  ros::Time time;
  time.fromNSec(stamp);
  return time;
}
}  // namespace

CartPoleSimNode::CartPoleSimNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                 ros::CallbackQueue* command_queue)
  : nh_(nh), pnh_(pnh)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  readParameters();
  simulation_ = std::make_unique<CartPoleSimulation>(physics_, start_state_bound_, seed_);
  noise_ = std::make_unique<RandomStream>(seed_, kNoiseStream);

  if (mode_ == Mode::Lockstep)
    joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>(
        "joint_states", 10,
        [this](const ros::SingleSubscriberPublisher& subscriber) { onSubscriberConnect(subscriber); });
  else
    joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  if (publish_clock_)
    clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ros::NodeHandle command_nh(nh_);
  if (command_queue != nullptr)
    command_nh.setCallbackQueue(command_queue);
  // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
  command_sub_ = command_nh.subscribe("joint_command", 10, &CartPoleSimNode::onJointCommand, this,
                                      ros::TransportHints().tcpNoDelay());
  effort_sub_ =
      command_nh.subscribe("cart_effort", 10, &CartPoleSimNode::onEffort, this, ros::TransportHints().tcpNoDelay());
  reset_srv_ = pnh_.advertiseService("reset", &CartPoleSimNode::onReset, this);

  // The first state: a random start, which takes one tick of sim time like every reset.
  simulation_->resetRandom();
  if (mode_ == Mode::Lockstep)
  {
    lockstep_ = std::make_unique<SimProtocol>(tickOf(physics_.tau), wallDuration(lockstep_timeout_));
    // A state that reaches no controller (one that subscribes late or restarts) is sent again
    // after lockstep_timeout; the timer looks twice per timeout.
    timer_ = nh_.createSteadyTimer(ros::WallDuration(lockstep_timeout_ / 2), &CartPoleSimNode::onLockstepTimer, this);
    publishState(toRosTime(lockstep_->start(WallClock::now())));
  }
  else
  {
    hold_ = std::make_unique<CommandHold>(wallDuration(command_timeout_));
    timer_ = nh_.createSteadyTimer(ros::WallDuration(physics_.tau), &CartPoleSimNode::onRealtimeTick, this);
    publishState(ros::Time::now());
  }
  ROS_INFO("cartpole_sim: %s mode, tau %g s, integrator %s, seed %llu, start state [%g, %g, %g, %g]%s",
           mode_ == Mode::Lockstep ? "lockstep" : "realtime", physics_.tau, toString(physics_.integrator).c_str(),
           static_cast<unsigned long long>(seed_), simulation_->state()[0], simulation_->state()[1],
           simulation_->state()[2], simulation_->state()[3], publish_clock_ ? ", publishing /clock" : "");
}

void CartPoleSimNode::readParameters()
{
  readPhysics(RosParameterSource(nh_), physics_, start_state_bound_);

  // Private parameters: the same reader and checks as the shared sections; a key it does not
  // know (a typo such as lockstep_timout) stops the node instead of being ignored.
  const RosParameterSource source(pnh_);
  SectionReader priv(source, "");
  std::string mode = "realtime";
  priv.readChoice("mode", mode, {"realtime", "lockstep"});
  mode_ = mode == "lockstep" ? Mode::Lockstep : Mode::Realtime;
  priv.read("seed", seed_, 0);
  priv.readAtLeast("command_timeout", command_timeout_, 0.0, true);
  priv.readAtLeast("lockstep_timeout", lockstep_timeout_, 0.0, true);
  priv.readAtLeast("tf_rate", tf_rate_, 0.0, true);
  effort_limit_ = physics_.force_mag;
  priv.readAtLeast("effort_limit", effort_limit_, 0.0, true);
  if (effort_limit_ > physics_.force_mag)
    priv.fail("effort_limit", SectionReader::numberText(effort_limit_),
              "must be <= physics/force_mag = " + SectionReader::numberText(physics_.force_mag));
  priv.readAtLeast("position_noise_std", position_noise_std_, 0.0, false);
  priv.readAtLeast("velocity_noise_std", velocity_noise_std_, 0.0, false);
  priv.readAtLeast("effort_noise_std", effort_noise_std_, 0.0, false);
  priv.read("publish_clock", publish_clock_);
  priv.read("publish_tf", publish_tf_);
  priv.read("track_y", track_y_);
  if (!std::isfinite(track_y_))
    priv.fail("track_y", SectionReader::numberText(track_y_), "must be finite");
  for (const auto& [name, frame] : {std::pair<const char*, std::string*>{"world_frame", &world_frame_},
                                    {"cart_frame", &cart_frame_},
                                    {"pole_frame", &pole_frame_}})
  {
    priv.read(name, *frame);
    if (frame->empty())
      priv.fail(name, "''", "frame names must not be empty");
  }
  priv.refuseUnknown();
  if (publish_clock_ && mode_ != Mode::Lockstep)
    priv.fail("publish_clock", "true", "only in lockstep mode: in realtime the wall clock is the clock");
}

bool CartPoleSimNode::acceptEffort(double requested, double& effort) const
{
  if (!std::isfinite(requested))
  {
    if (nonfinite_warning_.ready())
      ROS_WARN("cartpole_sim: refused a non-finite effort (%f)", requested);
    return false;
  }
  effort = std::clamp(requested, -effort_limit_, effort_limit_);
  if (effort != requested && clamp_warning_.ready())
    ROS_WARN("cartpole_sim: effort %g N clamped to the limit of %g N", requested, effort_limit_);
  return true;
}

void CartPoleSimNode::onJointCommand(const sensor_msgs::JointStateConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const Reading<double> requested = effortFromCommand(*msg);
  if (!requested)
  {
    if (bad_command_warning_.ready())
      ROS_WARN("cartpole_sim: %s", requested.refusal.c_str());
    return;
  }
  double effort = 0.0;
  if (!acceptEffort(*requested.value, effort))
    return;
  const WallClock::time_point now = WallClock::now();
  if (mode_ == Mode::Realtime)
  {
    if (!hold_->set(effort, msg->header.stamp.toNSec(), now))
      ROS_DEBUG("cartpole_sim: dropped a joint_command older than the one held");
    return;
  }
  apply(lockstep_->onCommand(msg->header.stamp.toNSec(), now), effort, msg->header.stamp);
}

void CartPoleSimNode::onEffort(const std_msgs::Float64ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  double effort = 0.0;
  if (!acceptEffort(msg->data, effort))
    return;
  const WallClock::time_point now = WallClock::now();
  if (mode_ == Mode::Realtime)
  {
    hold_->set(effort, 0, now);
    return;
  }
  apply(lockstep_->onUnstampedCommand(now), effort, ros::Time());
}

void CartPoleSimNode::apply(SimProtocol::Verdict verdict, double effort, const ros::Time& answers)
{
  if (verdict == SimProtocol::Verdict::Step)
  {
    advance(effort, toRosTime(lockstep_->pending()));
    return;
  }
  if (!dropped_warning_.ready())
    return;
  const SimProtocol::Counts& c = lockstep_->counts();
  // Stale and duplicate answers are expected now and then (a reset with an answer in flight, a
  // repeat answered twice); future and unstamped ones come from a misbehaving publisher.
  char text[320];
  std::snprintf(text, sizeof text,
                "cartpole_sim: dropped a joint_command stamped %.6f for the state at %.6f: %s (dropped so far: %llu "
                "stale, %llu duplicate, %llu future, %llu unstamped)",
                answers.toSec(), toRosTime(lockstep_->pending()).toSec(), describe(verdict),
                static_cast<unsigned long long>(c.stale), static_cast<unsigned long long>(c.duplicate),
                static_cast<unsigned long long>(c.future), static_cast<unsigned long long>(c.unstamped));
  // Stale and duplicate answers are expected now and then (a reset with an answer in flight, a
  // repeat answered twice); future and unstamped ones come from a misbehaving publisher.
  if (verdict == SimProtocol::Verdict::Stale || verdict == SimProtocol::Verdict::Duplicate)
    ROS_INFO("%s", text);
  else
    ROS_WARN("%s", text);
}

void CartPoleSimNode::advance(double effort, const ros::Time& stamp)
{
  double force = effort;
  if (effort_noise_std_ > 0.0)
    force = std::clamp(effort + effort_noise_std_ * noise_->normal(), -effort_limit_, effort_limit_);
  simulation_->step(force);
  publishState(stamp);
}

void CartPoleSimNode::onRealtimeTick(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  advance(hold_->effort(WallClock::now()), ros::Time::now());
}

void CartPoleSimNode::onLockstepTimer(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!lockstep_->repeatDue(WallClock::now()))
    return;
  ROS_DEBUG("cartpole_sim: no command for %.3f s, publishing the state again", lockstep_timeout_);
  republishState();
}

void CartPoleSimNode::onSubscriberConnect(const ros::SingleSubscriberPublisher& subscriber)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  // Harmless to anyone: a controller that already has this state takes it as a repeat.
  if (joint_state_)
    subscriber.publish(joint_state_);
}

bool CartPoleSimNode::onReset(Reset::Request& request, Reset::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
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
  // In lockstep a reset takes one tick of sim time, so the new start state never shares a stamp
  // with the state before it, and an answer to that state still in flight is dropped.
  publishState(mode_ == Mode::Lockstep ? toRosTime(lockstep_->onReset(WallClock::now())) : ros::Time::now());
  const CartPoleState& s = simulation_->state();
  std::ostringstream out;
  out.precision(17);
  out << "reset to [" << s[0] << ", " << s[1] << ", " << s[2] << ", " << s[3] << "]";
  response.success = true;
  response.message = out.str();
  return true;
}

void CartPoleSimNode::republishState()
{
  if (publish_clock_)
  {
    rosgraph_msgs::Clock clock;
    clock.clock = joint_state_->header.stamp;
    clock_pub_.publish(clock);
  }
  joint_state_pub_.publish(joint_state_);
}

void CartPoleSimNode::publishState(const ros::Time& stamp)
{
  const CartPoleState& s = simulation_->state();
  auto msg = boost::make_shared<sensor_msgs::JointState>(jointStateFromState(s, simulation_->appliedForce(), stamp));
  if (position_noise_std_ > 0.0)
  {
    msg->position[0] += position_noise_std_ * noise_->normal();
    msg->position[1] += position_noise_std_ * noise_->normal();
  }
  if (velocity_noise_std_ > 0.0)
  {
    msg->velocity[0] += velocity_noise_std_ * noise_->normal();
    msg->velocity[1] += velocity_noise_std_ * noise_->normal();
  }
  joint_state_ = msg;
  republishState();

  if (!publish_tf_)
    return;
  const WallClock::time_point wall_now = WallClock::now();
  if (mode_ == Mode::Lockstep && wall_now - last_tf_ < wallDuration(1.0 / tf_rate_))
    return;
  last_tf_ = wall_now;
  tf_broadcaster_.sendTransform(transformsFromState(s, track_y_, stamp, world_frame_, cart_frame_, pole_frame_));
}

}  // namespace cartpole_qlearning
