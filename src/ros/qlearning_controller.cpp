#include "cartpole_qlearning/ros/qlearning_controller.h"

#include "cartpole_qlearning/ros/conversions.h"
#include "cartpole_qlearning/ros/launch_control.h"
#include "cartpole_qlearning/ros/parameter_source.h"

#include <ros/names.h>
#include <ros/package.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include <unistd.h>

namespace cartpole_qlearning
{
namespace
{
double secondsSince(std::chrono::steady_clock::time_point then)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - then).count();
}

// The prefix of the node's lines: written here only.
std::string prefixed(const LogLine& log)
{
  return log.prefixed ? "qlearning_controller: " + log.text : log.text;
}
}  // namespace

QLearningControllerNode::QLearningControllerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                                 std::function<void()> shutdown, bool shutdown_by_default,
                                                 ros::CallbackQueue* state_queue)
  : nh_(nh), pnh_(pnh), shutdown_(std::move(shutdown))
{
  std::unique_lock<std::mutex> lock(mutex_);
  readParameters(shutdown_by_default);
  session_ = std::make_unique<TrainingSession>(settings_.training.task, settings_.training.agent, settings_.run.seed,
                                               settings_.run.learning, settings_.robots.size());
  if (settings_.run.trace && settings_.run.learning)
  {
    state_names_ = stateNames(settings_.training.agent);
    session_->setTrace([this](std::size_t robot, const TraceStep& step) {
      const std::string& name = settings_.robots[robot];
      say({{LogLine::Level::Info,
            (settings_.robots.size() > 1 ? name + ": " : "") +
                traceLine(step, state_names_, settings_.training.agent.actions),
            false}});
    });
  }
  startRun();
  stats_pub_ = nh_.advertise<EpisodeStats>("episode_stats", 100);
  save_srv_ = pnh_.advertiseService("save_q_table", &QLearningControllerNode::onSave, this);
  load_srv_ = pnh_.advertiseService("load_q_table", &QLearningControllerNode::onLoad, this);
  setUpRobots(state_queue);
  if (settings_.protocol.reset_service)
  {
    // docs/nodes.md: the ~reset_service row.
    const auto give_up_after = resetGiveUpAfter(settings_.sim_timeout);
    for (Robot& robot : robots_)
      robot.resetter = std::make_unique<ResetCaller>(robot.nh.resolveName(settings_.reset_service),
                                                     settings_.reset_service_type, give_up_after);
  }
  watchdog_ = nh_.createSteadyTimer(ros::WallDuration(std::min(0.5, settings_.sim_timeout / 2.0)),
                                    &QLearningControllerNode::onWatchdog, this);
  std::string served;
  for (const Robot& robot : robots_)
    served += (served.empty() ? "" : ", ") + describe(robot);
  say(LogLine::Level::Info, "%s",
      controllerStartText(settings_, session_->table(), app_->tableDirectory(), served).c_str());
  lock.unlock();
  startLiveTuning();
}

void QLearningControllerNode::setUpRobots(ros::CallbackQueue* state_queue)
{
  rounds_ = std::make_unique<RobotRounds>(
      settings_.robots.size(), settings_.sync,
      std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(settings_.sim_timeout)));
  robots_.resize(settings_.robots.size());
  const auto now = std::chrono::steady_clock::now();
  for (std::size_t r = 0; r < robots_.size(); ++r)
  {
    Robot& robot = robots_[r];
    robot.name = settings_.robots[r];
    ControllerProtocolParams params = settings_.protocol;
    params.robot = r;
    robot.protocol = std::make_unique<ControllerProtocol>(*session_, params);
    robot.nh = robot.name.empty() ? nh_ : ros::NodeHandle(nh_, robot.name);
    robot.command = CommandPublisher(robot.nh, settings_.robot.command_topic, settings_.robot);
    robot.mapping = std::make_unique<StateMapping>(settings_.robot);
    robot.decisions = std::make_unique<DecisionClock>(settings_.robot.decision_period);
    if (!robot.name.empty())
      robot.stats_pub = robot.nh.advertise<EpisodeStats>("episode_stats", 100);
    robot.last_state_at = now;
    ros::NodeHandle state_nh(robot.nh);
    if (state_queue != nullptr)
      state_nh.setCallbackQueue(state_queue);
    // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
    robot.state_sub = state_nh.subscribe<sensor_msgs::JointState>(
        settings_.robot.state_topic, 10,
        [this, r](const sensor_msgs::JointStateConstPtr& msg) { onJointState(r, msg); }, ros::VoidConstPtr(),
        ros::TransportHints().tcpNoDelay());
  }
}

QLearningControllerNode::~QLearningControllerNode()
{
  // First, with mutex_ free: a reconfigure call under way ends (it takes mutex_), no other starts.
  reconfigure_.reset();
  // Resets end here; a call under way is given up, not waited for (it may hang for minutes), so
  // the save below still happens. Under mutex_: a state callback or the watchdog may be asking
  // for a reset at this moment (in a nodelet they run on other threads).
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (Robot& robot : robots_)
      robot.resetter.reset();
  }
  // No state callback may run during the save (in a nodelet they run on another thread).
  for (Robot& robot : robots_)
    robot.state_sub.shutdown();
  const std::lock_guard<std::mutex> lock(mutex_);
  // ROS may be shut down already: said on the console.
  for (const LogLine& log : app_ ? app_->shutdown() : LogLines())
    std::printf("%s\n", prefixed(log).c_str());
  // Out now: under roslaunch stdout is a pipe, and a process killed after its slow exit (a
  // loaded machine) would lose what is still buffered (seen in a new Debian 12 root: the line
  // cut after the path).
  std::fflush(stdout);
}

void QLearningControllerNode::readParameters(bool shutdown_by_default)
{
  ControllerContext context;
  context.name_space = nh_.getNamespace();
  const char* home = std::getenv("HOME");
  context.home = home ? home : "";
  context.shutdown_by_default = shutdown_by_default;
  context.name_error = [](const std::string& name) {
    std::string error;
    return ros::names::validate(name, error) ? std::string() : error;
  };
  // Live tuning's values, which the controller's own dynamic_reconfigure server keeps there.
  for (const auto& param : LearningConfig::__getParamDescriptions__())
    context.other_keys.push_back(param->name);
  context.suite_folders = {ros::package::getPath("cartpole_qlearning") + "/config"};
  settings_ = readControllerSettings(RosParameterSource(nh_), RosParameterSource(pnh_), context);
}

bool QLearningControllerNode::extractState(Robot& robot, const sensor_msgs::JointState& msg, CartPoleState& state) const
{
  const Reading<JointReadings> reading =
      readingsFromJointState(msg, settings_.robot.cart_joint, settings_.robot.pole_joint);
  if (!reading)
  {
    if (bad_state_warning_.ready())
      say(LogLine::Level::Warn, "%s", reading.refusal.c_str());
    return false;
  }
  state = robot.mapping->map(msg.header.stamp.toNSec(), *reading.value);
  return true;
}

std::string QLearningControllerNode::describe(const Robot& robot) const
{
  return robot.state_sub.getTopic().empty() ? robot.name : robot.state_sub.getTopic();
}

void QLearningControllerNode::command(Robot& robot, double effort, const ros::Time& stamp)
{
  robot.command.publish(effort, stamp);
}

void QLearningControllerNode::stop()
{
  // Without mutex_, which a state callback running on another thread (a nodelet's) holds till it returns.
  for (Robot& robot : robots_)
    robot.state_sub.shutdown();
  const std::lock_guard<std::mutex> lock(mutex_);
  for (Robot& robot : robots_)
    robot.command.stop();
}

void QLearningControllerNode::onJointState(std::size_t r, const sensor_msgs::JointStateConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  CartPoleState state;
  Robot& robot = robots_[r];
  if (app_->finished() || !extractState(robot, *msg, state))
    return;
  robot.last_state_at = std::chrono::steady_clock::now();
  if (robot.silent_reported)
  {
    robot.silent_reported = false;
    say(LogLine::Level::Info, "joint_states are back on %s; going on", describe(robot).c_str());
  }
  if (rounds_->heard(r, robot.last_state_at))
    say(LogLine::Level::Info, "%s takes part in the rounds again", describe(robot).c_str());

  const ros::Time stamp = msg->header.stamp;
  const DecisionClock::Verdict decision = robot.decisions->onState(stamp.toNSec());
  if (decision.slow && slow_states_warning_.ready())
    say(LogLine::Level::Warn,
        "joint_states on %s come further apart than ~decision_period = %g s, the step the table learns",
        describe(robot).c_str(), settings_.robot.decision_period);
  // A fall ends the running episode whenever it comes, not a period later.
  const bool falls =
      robot.protocol->phase() == ControllerProtocol::Phase::InEpisode && session_->task().isTerminal(state);
  if (!decision.decide && !falls)
    return robot.command.hold(stamp);
  if (!rounds_->holds() || !robot.protocol->takesAsNew(stamp.toNSec()))
  {
    serve(r, stamp, state);
    return;
  }
  robot.held_stamp = stamp;
  robot.held_state = state;
  rounds_->hold(r);
  serveRounds();
}

void QLearningControllerNode::serveRounds()
{
  while (!app_->finished() && rounds_->roundComplete())
  {
    for (std::size_t r = 0; r < robots_.size() && !app_->finished(); ++r)
    {
      if (!rounds_->held(r))
        continue;
      rounds_->take(r);
      serve(r, robots_[r].held_stamp, robots_[r].held_state);
    }
  }
}

void QLearningControllerNode::serve(std::size_t r, const ros::Time& stamp, const CartPoleState& state)
{
  Robot& robot = robots_[r];
  const Reaction reaction = robot.protocol->onState(stamp.toNSec(), state);
  report(robot, reaction, stamp);
  if (reaction.answer)
    command(robot, reaction.effort, stamp);
  if (reaction.episode_ended && !reaction.answer)
    robot.command.stop();
  if (reaction.episode_ended)
    endEpisode(robot, stamp, reaction.training_finished);
  if (reaction.request_reset && !app_->finished())
    requestReset(r);
}

void QLearningControllerNode::report(const Robot& robot, const Reaction& reaction, const ros::Time& stamp)
{
  say(reactionLog(
      reaction, robot.protocol->counts(), describe(robot), stamp.toSec(),
      [this] { return dropped_state_warning_.ready(); }, [this] { return restart_warning_.ready(); }));
}

void QLearningControllerNode::endEpisode(Robot& robot, const ros::Time& stamp, bool training_finished)
{
  // The curve's row, rates, checkpoints and, when training ends here, the final save: before
  // episode_stats says so, so that whoever acts on the last message finds the final file.
  const EpisodeEnd end = app_->endEpisode(robot.name, training_finished);
  if (end.run_folder && !app_->identity().id.empty())
    pnh_.setParam("run/folder", *end.run_folder);
  const EpisodeSummary& s = session_->lastEpisode();

  EpisodeStats stats = learnerEpisodeStats(s, robot.name, stamp, end.steps_per_second);
  stats.robustness = end.robustness;
  stats_pub_.publish(stats);
  if (robot.stats_pub)
    robot.stats_pub.publish(robotEpisodeStats(s, robot.name, stamp, end.robot_steps_per_second));

  say(end.log);
  if (end.finished)
    endWhenFinished();
}

void QLearningControllerNode::endWhenFinished()
{
  if (!settings_.shutdown_when_finished)
    return;
  if (endParentLaunch())
  {
    say(LogLine::Level::Info, "done; ending the launch");
    return;
  }
  if (shutdown_)
    shutdown_();
}

void QLearningControllerNode::startRun()
{
  app_ = std::make_unique<RunApplication>(settings_.run, settings_.training, *session_);
  // A respawn finds the run id, the roslaunch (else the parent) and the folder of the process
  // that started the run; a node started by hand on a reused master has at most the id left there.
  RunIdentity previous;
  pnh_.getParam("run/id", previous.id);
  pnh_.getParam("run/launcher", previous.launcher);
  pnh_.getParam("run/folder", previous.folder);
  const pid_t roslaunch = launchingRoslaunch();
  try
  {
    say(app_->start(previous, static_cast<int>(roslaunch > 0 ? roslaunch : ::getppid())));
  }
  catch (const RunSettingError& e)
  {
    refuseParameter(pnh_, e.name, e.value, e.why);
  }
  const RunIdentity identity = app_->identity();
  if (!app_->respawned() && !identity.id.empty())
  {
    pnh_.setParam("run/id", identity.id);
    pnh_.setParam("run/launcher", identity.launcher);
    pnh_.setParam("run/folder", identity.folder);
  }
  // A respawn of a run that has finished stays up rather than exit (under respawn that would
  // only start it again), and ends the launch when asked to.
  if (app_->finished() && settings_.shutdown_when_finished && endParentLaunch())
    say(LogLine::Level::Info, "ending the launch");
}

bool QLearningControllerNode::onSave(SaveQTable::Request& request, SaveQTable::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const ServiceAnswer answer = app_->save(request.path);
  response.success = answer.success;
  response.message = answer.message;
  say(answer.log);
  return true;
}

bool QLearningControllerNode::onLoad(LoadQTable::Request& request, LoadQTable::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const ServiceAnswer answer = app_->load(request.path);
  response.success = answer.success;
  response.message = answer.message;
  say(answer.log);
  return true;
}

void QLearningControllerNode::onWatchdog(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (app_->finished())
    return;
  for (Robot& robot : robots_)
  {
    if (robot.silent_reported || secondsSince(robot.last_state_at) < settings_.sim_timeout)
      continue;
    robot.silent_reported = true;
    robot.command.stop();
    say(LogLine::Level::Warn, "no joint_states on %s for %.1f s: is its cartpole_sim running? Waiting for it",
        describe(robot).c_str(), settings_.sim_timeout);
  }
  const std::vector<std::size_t> dropped = rounds_->dropOuts(WallClock::now());
  for (const std::size_t r : dropped)
    say(LogLine::Level::Warn, "%s is silent; the rounds go on without it until it is back", describe(robots_[r]).c_str());
  if (!dropped.empty())
    serveRounds();
}

void QLearningControllerNode::startLiveTuning()
{
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // The server starts from what it finds on the parameter server. A respawn finds the values
    // its predecessor served, the live tuning of this run, and goes on with them (onReconfigure
    // says so). A new run starts from its configuration: what an earlier node left is replaced.
    if (!app_->respawned())
    {
      const LearningSettings& running = session_->learningSettings();
      LearningConfig left = toConfig(running);
      left.__fromServer__(pnh_);  // only the fields present there change
      LearningSettings left_settings = running;
      fromConfig(left, left_settings);
      say(liveTuningReplacedLog(left_settings, running));
      toConfig(session_->learningSettings()).__toServer__(pnh_);
    }
  }
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<LearningConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_->setCallback([this](LearningConfig& config, std::uint32_t level) { onReconfigure(config, level); });
}

void QLearningControllerNode::onReconfigure(LearningConfig& config, std::uint32_t)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const bool first = !reconfigure_started_;
  reconfigure_started_ = true;
  const LearningSettings in_use = session_->learningSettings();
  LearningSettings wanted = in_use;
  std::string error = fromConfig(config, wanted);
  if (error.empty())
    error = session_->setLearning(wanted);
  // What the server keeps, answers and publishes: the values in use (a refused change undone,
  // an override given as any negative number shown as -1).
  config = toConfig(session_->learningSettings());
  say(liveTuningLog(in_use, wanted, asServerField(error), first && app_->respawned(), settings_.run.learning));
}

void QLearningControllerNode::requestReset(std::size_t robot)
{
  // None once the destructor has begun.
  if (robots_.at(robot).resetter)
    robots_.at(robot).resetter->request();
}

void QLearningControllerNode::say(const LogLines& log) const
{
  for (const LogLine& line : log)
  {
    switch (line.level)
    {
      case LogLine::Level::Info:
        ROS_INFO_STREAM_NAMED("qlearning_controller", prefixed(line));
        break;
      case LogLine::Level::Warn:
        ROS_WARN_STREAM_NAMED("qlearning_controller", prefixed(line));
        break;
      case LogLine::Level::Error:
        ROS_ERROR_STREAM_NAMED("qlearning_controller", prefixed(line));
        break;
    }
  }
}

void QLearningControllerNode::say(LogLine::Level level, const char* format, ...) const
{
  std::va_list args;
  va_start(args, format);
  const std::string text = formatTextV(format, args);
  va_end(args);
  say({{level, text}});
}

}  // namespace cartpole_qlearning
