#include "cartpole_qlearning/ros/command_watchdog.h"

#include "command_publisher.h"
#include "parameter_source.h"
#include "start_up.h"

#include "cartpole_qlearning/node_settings/node_setting_names.h"
#include "cartpole_qlearning/node_settings/robot_settings.h"
#include "cartpole_qlearning/ros/conversions.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace cartpole_qlearning
{
namespace
{
constexpr double kNotANumber = std::numeric_limits<double>::quiet_NaN();

// The effort a command carries, NaN when it carries none (a malformed command is no number).
double effortOf(const sensor_msgs::JointState& msg, const RobotInterfaceParams& robot)
{
  const Reading<double> effort = effortFromCommand(msg, robot.command_joint);
  return effort ? *effort.value : kNotANumber;
}
double effortOf(const std_msgs::Float64& msg, const RobotInterfaceParams&)
{
  return msg.data;
}
double effortOf(const std_msgs::Float64MultiArray& msg, const RobotInterfaceParams& robot)
{
  return robot.command_index < msg.data.size() ? msg.data[robot.command_index] : kNotANumber;
}
}  // namespace

CommandWatchdogNode::CommandWatchdogNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
  : nh_(nh),
    pnh_(pnh),
    name_(nodeLogger("command_watchdog", pnh.getNamespace())),
    watchdog_(
        (readParameters(), std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(timeout_s_))),
        nodeSettingNames())
{
  out_ = std::make_unique<CommandPublisher>(nh_, robot_.command_topic, robot_);
  // No Nagle delay on the way in: each command is one small message that the robot waits for.
  const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
  switch (robot_.command_type)
  {
    case CommandType::JointState:
      in_ = pnh_.subscribe("controller_command", 10, &CommandWatchdogNode::onCommand<sensor_msgs::JointState>, this,
                           hints);
      break;
    case CommandType::Float64:
      in_ = pnh_.subscribe("controller_command", 10, &CommandWatchdogNode::onCommand<std_msgs::Float64>, this, hints);
      break;
    case CommandType::Float64Array:
      in_ = pnh_.subscribe("controller_command", 10, &CommandWatchdogNode::onCommand<std_msgs::Float64MultiArray>, this,
                           hints);
      break;
  }
  // The timeout is judged, and a lost publisher seen, at the next tick: a tenth of the timeout,
  // at most 10 ms, stops the robot within a tick of either.
  const double tick = timeout_s_ > 0.0 ? std::min(0.01, timeout_s_ / 10.0) : 0.01;
  timer_ = nh_.createWallTimer(ros::WallDuration(tick), &CommandWatchdogNode::onTick, this);
  say({{LogLine::Level::Info, "forwarding " + in_.getTopic() + " to " + nh_.resolveName(robot_.command_topic) +
                                  (timeout_s_ > 0.0 ? formatText(", 0 after %.3f s without a command", timeout_s_)
                                                    : std::string(", no timeout")) +
                                  ", at once when the controller's publisher goes"}});
}

CommandWatchdogNode::~CommandWatchdogNode() = default;

void CommandWatchdogNode::readParameters()
{
  RosParameterSource source(pnh_);
  SectionReader priv(source, "");
  priv.read("command_topic", robot_.command_topic);
  if (robot_.command_topic.empty())
    priv.fail("command_topic", "''", "must name the robot's command topic");
  priv.read("cart_joint", robot_.cart_joint);
  readRobotCommand(priv, robot_);
  // The controller commands at least once a decision period while it acts (a Float64 robot gets
  // nothing between decisions): five of them (0.1 s at the usual 0.02) leave room for a loaded
  // machine's jitter, as the controller's own freshness guard does, and still stop a robot whose
  // controller died within a tenth of a second.
  double decision_period = 0.02;
  priv.readSeconds("decision_period", decision_period, 0.0, 1.0, false);
  timeout_s_ = std::max(0.1, 5.0 * decision_period);
  // Over a second a falling pole is down: a watchdog that waits longer guards nothing.
  priv.readSeconds("timeout", timeout_s_, 0.0, 1.0, false);
}

template <class Message>
void CommandWatchdogNode::onCommand(const boost::shared_ptr<const Message>& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  LogLines log;
  // The count first: a command that comes after its publisher's link closed is a stray.
  carryOut(watchdog_.onPublishers(in_.getNumPublishers(), log));
  const CommandWatchdog::Action action = watchdog_.onCommand(effortOf(*msg, robot_), WallClock::now(), log);
  if (action == CommandWatchdog::Action::Forward)
    out_->forward(msg);
  else
    carryOut(action);
  say(log);
}

void CommandWatchdogNode::onTick(const ros::WallTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  LogLines log;
  carryOut(watchdog_.onPublishers(in_.getNumPublishers(), log));
  carryOut(watchdog_.onTick(WallClock::now(), log));
  say(log);
}

void CommandWatchdogNode::stop()
{
  const std::lock_guard<std::mutex> lock(mutex_);
  LogLines log;
  timer_.stop();
  carryOut(watchdog_.onShutdown(log));
  say(log);
}

void CommandWatchdogNode::carryOut(CommandWatchdog::Action action)
{
  if (action == CommandWatchdog::Action::SendZero)
    out_->stop();
}

void CommandWatchdogNode::say(const LogLines& log)
{
  for (const LogLine& line : log)
    logLine(name_, line.level, withPrefix("command_watchdog: ", line));
}

}  // namespace cartpole_qlearning
