#include "cartpole_qlearning/protocol/robot_dispatch.h"

#include <algorithm>
#include <chrono>

namespace cartpole_qlearning
{
namespace
{
ControllerProtocolParams protocolParams(const RobotDispatchParams& params, std::size_t robot)
{
  ControllerProtocolParams protocol = params.protocol;
  protocol.robot = robot;
  return protocol;
}

WallClock::duration wallDuration(double seconds)
{
  return std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(seconds));
}

// A stamp in seconds as ros::Time::toSec computes it, so that the lines print what they printed
// when the node had the message's stamp at hand.
double stampSeconds(Stamp stamp)
{
  return static_cast<double>(stamp / 1000000000ULL) + 1e-9 * static_cast<double>(stamp % 1000000000ULL);
}
}  // namespace

RobotDispatch::Robot::Robot(TrainingSession& session, const RobotDispatchParams& params, std::size_t index)
  : name(params.robots.at(index)),
    protocol(session, protocolParams(params, index)),
    mapping(params.robot),
    decisions(params.robot.decision_period),
    guard(wallDuration(params.freshness_timeout_s), params.robots.at(index))
{
}

RobotDispatch::RobotDispatch(TrainingSession& session, const RobotDispatchParams& params, WallClock::time_point now)
  : session_(session),
    params_(params),
    rounds_(params.robots.size(), params.sync, wallDuration(params.silent_after_s), now)
{
  robots_.reserve(params.robots.size());
  for (std::size_t r = 0; r < params.robots.size(); ++r)
    robots_.emplace_back(session, params, r);
}

double RobotDispatch::tickSeconds() const
{
  double tick = std::min(0.5, params_.silent_after_s / 2.0);
  if (params_.freshness_timeout_s > 0.0)
    tick = std::min(tick, params_.freshness_timeout_s / 4.0);
  return tick;
}

RobotDispatch::Orders RobotDispatch::onInvalid(std::size_t r, Stamp stamp, WallClock::time_point now,
                                               const std::string& publisher)
{
  Orders orders;
  robots_.at(r).last_message = now;
  robots_.at(r).guard.onMessage(stamp, false, publisher, now, orders.log);
  orders.drop = true;
  return orders;
}

RobotDispatch::Orders RobotDispatch::onState(std::size_t r, Stamp stamp, const JointReadings& readings,
                                             WallClock::time_point now, const std::string& publisher)
{
  Robot& robot = robots_.at(r);
  Orders orders;
  robot.last_message = now;
  if (!robot.guard.onMessage(stamp, true, publisher, now, orders.log))
  {
    orders.drop = true;
    return orders;
  }
  const CartPoleState state = robot.mapping.map(stamp, readings);
  if (robot.silent_reported)
  {
    robot.silent_reported = false;
    orders.log.push_back({LogLine::Level::Info, "joint_states are back on " + robot.name + "; going on"});
  }
  if (rounds_.heard(r, now))
    orders.log.push_back({LogLine::Level::Info, robot.name + " takes part in the rounds again"});

  const DecisionClock::Verdict decision = robot.decisions.onState(stamp);
  if (decision.slow && slow_states_warning_.ready(now))
    orders.log.push_back({LogLine::Level::Warn,
                          formatText("joint_states on %s come further apart than %s = %g s, the step the table learns",
                                     robot.name.c_str(), params_.names(Setting::DecisionPeriod).c_str(),
                                     params_.robot.decision_period)});
  // A fall ends the running episode whenever it comes, not a period later.
  const bool falls =
      robot.protocol.phase() == ControllerProtocol::Phase::InEpisode && session_.task().isTerminal(state);
  if (!decision.decide && !falls)
  {
    orders.hold = true;
    orders.hold_zero = !robot.guard.mayPush(now);
    return orders;
  }
  // Only a state the protocol takes as new may learn and draw from the exploration stream: that
  // one waits for its round; a repeat or a dropped state is passed on at once.
  if (!rounds_.holds() || !robot.protocol.takesAsNew(stamp))
  {
    at_once_ = Waiting{r, stamp, state};
    return orders;
  }
  robot.held_stamp = stamp;
  robot.held_state = state;
  rounds_.hold(r);
  return orders;
}

RobotDispatch::Orders RobotDispatch::onTick(WallClock::time_point now)
{
  Orders orders;
  const WallClock::duration silent_after = wallDuration(params_.silent_after_s);
  for (std::size_t r = 0; r < robots_.size(); ++r)
  {
    Robot& robot = robots_[r];
    if (robot.guard.check(now, orders.log))
      orders.stop.push_back(r);
    if (robot.silent_reported || rounds_.silentFor(r, now) < silent_after)
      continue;
    robot.silent_reported = true;
    if (orders.stop.empty() || orders.stop.back() != r)
      orders.stop.push_back(r);
    const bool publishing = robot.last_message && now - *robot.last_message < silent_after;
    orders.log.push_back(
        {LogLine::Level::Warn,
         publishing
             ? formatText("no usable joint_states on %s for %.1f s: they keep coming, but none could be used (see "
                          "the warnings about them above). Waiting for usable ones",
                          robot.name.c_str(), params_.silent_after_s)
         : params_.simulated
             ? formatText("no joint_states on %s for %.1f s: is its cartpole_sim running? Waiting for it",
                          robot.name.c_str(), params_.silent_after_s)
             : formatText("no joint_states on %s for %.1f s: no driver publishes them. Is the robot's driver running, "
                          "and %s the topic it publishes? Waiting for it",
                          robot.name.c_str(), params_.silent_after_s, params_.names(Setting::StateTopic).c_str())});
  }
  for (const std::size_t r : rounds_.dropOuts(now))
    orders.log.push_back(
        {LogLine::Level::Warn, robots_[r].name + " is silent; the rounds go on without it until it is back"});
  return orders;
}

void RobotDispatch::onResetOutcome(std::size_t robot, bool succeeded)
{
  robots_.at(robot).protocol.onResetOutcome(succeeded);
}

std::optional<RobotDispatch::Turn> RobotDispatch::next(WallClock::time_point now)
{
  if (at_once_)
  {
    const Waiting waiting = *at_once_;
    at_once_.reset();
    return serve(waiting.robot, waiting.stamp, waiting.state, now);
  }
  // A round once complete is served to its end, robot by robot: serving one robot's state takes
  // it out of the round, which then no longer counts as complete.
  if (!in_round_ && !rounds_.roundComplete())
    return std::nullopt;
  in_round_ = true;
  for (std::size_t r = 0; r < robots_.size(); ++r)
  {
    if (!rounds_.held(r))
      continue;
    rounds_.take(r);
    return serve(r, robots_[r].held_stamp, robots_[r].held_state, now);
  }
  in_round_ = false;
  return next(now);
}

RobotDispatch::Turn RobotDispatch::serve(std::size_t r, Stamp stamp, const CartPoleState& state,
                                         WallClock::time_point now)
{
  Robot& robot = robots_[r];
  Turn turn;
  turn.robot = r;
  turn.stamp = stamp;
  turn.state = state;
  turn.reaction = robot.protocol.onState(stamp, state);
  turn.log = reactionLog(
      turn.reaction, robot.protocol.counts(), robot.name, stampSeconds(stamp),
      [&] { return dropped_state_warning_.ready(now); }, [&] { return restart_warning_.ready(now); }, params_.names);
  if (turn.reaction.kind == Reaction::Kind::New)
    robot.guard.onDecision(stamp, now, turn.log);
  // An effort goes out only while the guard allows it (a repeat's answer after the bound, say).
  if (turn.reaction.answer && !robot.guard.mayPush(now))
    turn.reaction.effort = 0.0;
  return turn;
}

}  // namespace cartpole_qlearning
