#include "cartpole_qlearning/ros/cartpole_sim.h"

#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/simulation/engine_registry.h"
#include "cartpole_qlearning/simulation/physics_engines.h"
#include "cartpole_qlearning/ros/conversions.h"
#include "parameter_source.h"
#include "start_up.h"

#include <rosgraph_msgs/Clock.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
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
  : nh_(nh), pnh_(pnh), name_(nodeLogger("cartpole_sim", pnh.getNamespace()))
{
  const std::lock_guard<std::mutex> lock(mutex_);
  readParameters();
  // The core's simulation, perturbations included, on the engine the config asks for (the equations
  // or a MuJoCo model), built by the factory train_headless builds its own with: the same seed and
  // config give the same episodes.
  try
  {
    simulation_ = std::make_unique<CartPoleSimulation>(makeSimulation(
        settings_.physics, settings_.engine, settings_.start_state_bound, settings_.seed, settings_.perturbations));
    // The task's starts, as train_headless draws them: a swing-up task's pole hangs.
    simulation_->setStart(settings_.start);
  }
  catch (const EngineError& e)
  {
    // A relative model without config_file was taken relative to the node's working folder (~/.ros).
    const bool unanchored = !settings_.engine.model.empty() && settings_.engine.model.front() != '/' &&
                            RosParameterSource(nh_).folder().empty();
    throw ConfigError(std::string(e.what()) +
                      (unanchored ? " (a relative physics/model is relative to the folder of the parameter " +
                                        nh_.resolveName("config_file") +
                                        ", which is not set: the launch files set it to their config)"
                                  : ""));
  }
  // TF shows the engine's bodies unless told other frames.
  if (settings_.cart_frame.empty())
    settings_.cart_frame = simulation_->engine().cartBody().empty() ? "cart" : simulation_->engine().cartBody();
  if (settings_.pole_frame.empty())
    settings_.pole_frame = simulation_->engine().poleBody().empty() ? "pole" : simulation_->engine().poleBody();

  if (settings_.mode == SimMode::Lockstep)
    joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>(
        "joint_states", 10,
        [this](const ros::SingleSubscriberPublisher& subscriber) { onSubscriberConnect(subscriber); });
  else
    joint_state_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  if (settings_.publish_clock)
    clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ros::NodeHandle command_nh(nh_);
  if (command_queue != nullptr)
    command_nh.setCallbackQueue(command_queue);
  // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
  command_sub_ = command_nh.subscribe("joint_command", 10, &CartPoleSimNode::onJointCommand, this,
                                      ros::TransportHints().tcpNoDelay());
  effort_sub_ =
      command_nh.subscribe("cart_effort", 10, &CartPoleSimNode::onEffort, this, ros::TransportHints().tcpNoDelay());
  group_effort_sub_ = command_nh.subscribe("group_effort", 10, &CartPoleSimNode::onGroupEffort, this,
                                           ros::TransportHints().tcpNoDelay());
  reset_srv_ = pnh_.advertiseService("reset", &CartPoleSimNode::onReset, this);
  reset_simulation_srv_ = pnh_.advertiseService("reset_simulation", &CartPoleSimNode::onResetSimulation, this);

  // The first state: a random start, which takes one tick of sim time like every reset.
  simulation_->resetRandom();
  const bool own_rate = settings_.publish_period != settings_.physics.tau;
  if (settings_.mode == SimMode::Lockstep)
  {
    // Stamps go by the publish period; the physics steps by tau in between (SampledPhysics).
    lockstep_ =
        std::make_unique<SimProtocol>(tickOf(settings_.publish_period), wallDuration(settings_.lockstep_timeout));
    sampled_ = std::make_unique<SampledPhysics>(tickOf(settings_.physics.tau), tickOf(settings_.publish_period));
    // A state that reaches no controller (one that subscribes late or restarts) is sent again
    // after lockstep_timeout; the timer looks twice per timeout.
    timer_ = nh_.createSteadyTimer(ros::WallDuration(settings_.lockstep_timeout / 2), &CartPoleSimNode::onLockstepTimer,
                                   this);
    const Stamp first = lockstep_->start(WallClock::now());
    sampled_->restart(first);
    publishState(toRosTime(first));
  }
  else
  {
    hold_ = std::make_unique<CommandHold>(wallDuration(settings_.command_timeout));
    timer_ = nh_.createSteadyTimer(ros::WallDuration(settings_.physics.tau), &CartPoleSimNode::onRealtimeTick, this);
    // Another rate: a sensor sampling the physics on a timer of its own.
    if (own_rate)
      publish_timer_ =
          nh_.createSteadyTimer(ros::WallDuration(settings_.publish_period), [this](const ros::SteadyTimerEvent&) {
            const std::lock_guard<std::mutex> lock(mutex_);
            publishState(ros::Time::now());
          });
    publishState(ros::Time::now());
  }
  const std::string engine = engineOf(settings_.engine).describe(settings_.physics, settings_.engine);
  say(ros::console::levels::Info,
      "cartpole_sim: %s mode, tau %g s, %s, seed %llu, starts of task %s, start state [%g, %g, %g, %g]%s%s",
      settings_.mode == SimMode::Lockstep ? "lockstep" : "realtime", settings_.physics.tau, engine.c_str(),
      static_cast<unsigned long long>(settings_.seed), toString(settings_.task).c_str(), simulation_->state()[0],
      simulation_->state()[1], simulation_->state()[2], simulation_->state()[3],
      settings_.publish_clock ? ", publishing /clock" : "",
      own_rate ? (", joint_states every " + SectionReader::numberText(settings_.publish_period) + " s").c_str() : "");
  if (!settings_.suite_case.empty())
    say(ros::console::levels::Info, "cartpole_sim: posing as case %s of %s", settings_.suite_case.c_str(),
        settings_.suite.c_str());
  if (settings_.perturbations.any())
    say(ros::console::levels::Info, "cartpole_sim: perturbations on (%s)",
        describePerturbations(settings_.perturbations, settings_.physics.tau).c_str());
}

void CartPoleSimNode::readParameters()
{
  settings_ = readSimSettings(RosParameterSource(nh_), RosParameterSource(pnh_));
}

bool CartPoleSimNode::acceptEffort(double requested, double& effort) const
{
  if (!std::isfinite(requested))
  {
    if (nonfinite_warning_.ready())
      say(ros::console::levels::Warn, "cartpole_sim: refused a non-finite effort (%f)", requested);
    return false;
  }
  effort = std::clamp(requested, -settings_.effort_limit, settings_.effort_limit);
  if (effort != requested && clamp_warning_.ready())
    say(ros::console::levels::Warn, "cartpole_sim: effort %g N clamped to the limit of %g N", requested,
        settings_.effort_limit);
  return true;
}

void CartPoleSimNode::onJointCommand(const sensor_msgs::JointStateConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const Reading<double> requested = effortFromCommand(*msg, settings_.pose.cart_joint);
  if (!requested)
  {
    if (bad_command_warning_.ready())
      say(ros::console::levels::Warn, "cartpole_sim: %s", requested.refusal.c_str());
    return;
  }
  double effort = 0.0;
  if (!acceptEffort(*requested.value, effort))
    return;
  const WallClock::time_point now = WallClock::now();
  if (settings_.mode == SimMode::Realtime)
  {
    if (!hold_->set(effort, msg->header.stamp.toNSec(), now))
      say(ros::console::levels::Debug, "cartpole_sim: dropped a joint_command older than the one held");
    return;
  }
  // An unstamped zero is a controller stopping (an episode's end, its shutdown): it answers no
  // state, so it is dropped without a warning.
  if (msg->header.stamp.isZero() && effort == 0.0)
    return;
  apply(lockstep_->onCommand(msg->header.stamp.toNSec(), now), effort, msg->header.stamp);
}

void CartPoleSimNode::onEffort(const std_msgs::Float64ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  onUnstampedEffort(msg->data);
}

void CartPoleSimNode::onGroupEffort(const std_msgs::Float64MultiArrayConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (msg->data.size() <= settings_.group_effort_index)
  {
    if (bad_command_warning_.ready())
      say(ros::console::levels::Warn, "cartpole_sim: dropped a group_effort of %zu values: the cart's is at index %llu",
          msg->data.size(), static_cast<unsigned long long>(settings_.group_effort_index));
    return;
  }
  onUnstampedEffort(msg->data[settings_.group_effort_index]);
}

void CartPoleSimNode::onUnstampedEffort(double requested)
{
  double effort = 0.0;
  if (!acceptEffort(requested, effort))
    return;
  const WallClock::time_point now = WallClock::now();
  if (settings_.mode == SimMode::Realtime)
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
    stepLockstep(effort);
    return;
  }
  const Stamp stamp = answers.toNSec();
  if (stamp >= passed_from_ && stamp <= passed_to_ && stamp != 0)
    return;  // a sample nobody waited for
  if (!dropped_warning_.ready())
    return;
  const SimProtocol::Counts& c = lockstep_->counts();
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
    say(ros::console::levels::Info, "%s", text);
  else
    say(ros::console::levels::Warn, "%s", text);
}

void CartPoleSimNode::step(double effort)
{
  // The delay, the motor factor and the pushes are the simulation's: in realtime the delay is
  // counted in ticks as in lockstep, delay_steps x tau seconds.
  simulation_->step(settings_.pose.effort_sign * effort);
}

void CartPoleSimNode::stepLockstep(double effort)
{
  const Stamp period = tickOf(settings_.publish_period);
  Stamp stamp = lockstep_->pending();  // the answered state's, one period on
  const std::uint64_t steps = sampled_->stepsAfter(stamp - period);
  // The state before the last step is shown only when that step ends after the stamp (samples
  // faster than the steps): else no message is made for it.
  const bool shown_before_last = sampled_->showsBeforeLastStep(stamp);
  for (std::uint64_t i = 0; i < steps; ++i)
  {
    if (i + 1 == steps && shown_before_last)
      before_last_step_ = stateMessage();
    step(effort);
  }
  publishState(toRosTime(stamp), sampled_->showsBeforeLastStep(stamp));
  passed_from_ = passed_to_ = 0;
  while (!sampled_->answerDrivesAStep(stamp))
  {
    if (passed_from_ == 0)
      passed_from_ = stamp;
    passed_to_ = stamp;
    lockstep_->onUnstampedCommand(WallClock::now());
    stamp = lockstep_->pending();
    publishState(toRosTime(stamp), sampled_->showsBeforeLastStep(stamp));
  }
}

void CartPoleSimNode::onRealtimeTick(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  step(hold_->effort(WallClock::now()));
  if (!publish_timer_.isValid())
    publishState(ros::Time::now());
}

void CartPoleSimNode::onLockstepTimer(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!lockstep_->repeatDue(WallClock::now()))
    return;
  say(ros::console::levels::Debug, "cartpole_sim: no command for %.3f s, publishing the state again",
      settings_.lockstep_timeout);
  republishState();
}

void CartPoleSimNode::onSubscriberConnect(const ros::SingleSubscriberPublisher& subscriber)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  // Harmless to anyone: a controller that already has this state takes it as a repeat.
  if (joint_state_)
    subscriber.publish(joint_state_);
}

bool CartPoleSimNode::onResetSimulation(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  simulation_->resetRandom();
  if (!lockstep_)
  {
    publishState(ros::Time::now());
    return true;
  }
  const Stamp first = lockstep_->onResetTimeBack(WallClock::now());
  sampled_->restart(first);
  publishState(toRosTime(first));
  return true;
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
  if (lockstep_)
  {
    const Stamp start = lockstep_->onReset(WallClock::now());
    sampled_->restart(start);
    publishState(toRosTime(start));
  }
  else
    publishState(ros::Time::now());
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
  if (settings_.publish_clock)
  {
    rosgraph_msgs::Clock clock;
    clock.clock = joint_state_->header.stamp;
    clock_pub_.publish(clock);
  }
  joint_state_pub_.publish(joint_state_);
}

sensor_msgs::JointStatePtr CartPoleSimNode::stateMessage() const
{
  // The effort as the robot's joint reads it, in its sign.
  return boost::make_shared<sensor_msgs::JointState>(jointStateFromReadings(
      robotReadings(settings_.pose, simulation_->observation(), settings_.pole_turns, settings_.publish_velocities),
      settings_.pose.effort_sign * simulation_->appliedForce(), ros::Time(), settings_.pose.cart_joint,
      settings_.pose.pole_joint));
}

void CartPoleSimNode::publishState(const ros::Time& stamp, bool before_last_step)
{
  // joint_states carry what the sensors read; TF shows the true state.
  const CartPoleState& s = simulation_->state();
  // A new message each time (a subscriber in the manager may hold the last one).
  auto msg = before_last_step && before_last_step_ ? boost::make_shared<sensor_msgs::JointState>(*before_last_step_)
                                                   : stateMessage();
  msg->header.stamp = stamp;
  joint_state_ = msg;
  republishState();

  if (!settings_.publish_tf)
    return;
  const WallClock::time_point wall_now = WallClock::now();
  if (settings_.mode == SimMode::Lockstep && wall_now - last_tf_ < wallDuration(1.0 / settings_.tf_rate))
    return;
  last_tf_ = wall_now;
  tf_broadcaster_.sendTransform(transformsFromState(s, settings_.track_y, stamp, settings_.world_frame,
                                                    settings_.cart_frame, settings_.pole_frame));
}

void CartPoleSimNode::say(ros::console::Level level, const char* format, ...) const
{
  std::va_list args;
  va_start(args, format);
  const std::string text = formatTextV(format, args);
  va_end(args);
  logLine(name_, level, text);
}

}  // namespace cartpole_qlearning
