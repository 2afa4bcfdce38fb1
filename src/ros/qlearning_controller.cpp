#include "cartpole_qlearning/ros/qlearning_controller.h"

#include "cartpole_qlearning/node_settings/node_setting_names.h"
#include "cartpole_qlearning/ros/conversions.h"
#include "command_publisher.h"
#include "control_reporter.h"
#include "launch_control.h"
#include "parameter_source.h"
#include "reset_caller.h"
#include "start_up.h"

#include <std_msgs/UInt32.h>

#include <cstdio>
#include <optional>
#include <utility>

#include <unistd.h>

namespace cartpole_qlearning
{
struct QLearningControllerNode::Robot
{
  std::string name;    // its namespace relative to the learner's ("" : the learner's own)
  ros::NodeHandle nh;  // in that namespace
  ros::Subscriber state_sub;
  CommandPublisher command;               // ~command_type on joint_command
  ros::Publisher stats_pub;               // only for a robot in a namespace of its own
  std::unique_ptr<ResetCaller> resetter;  // none without a reset service
};

// The prefix of the node's lines (withPrefix): written here only.
static const char* const kPrefix = "qlearning_controller: ";

QLearningControllerNode::QLearningControllerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                                 std::function<void()> shutdown, bool shutdown_by_default,
                                                 ros::CallbackQueue* state_queue)
  : nh_(nh), pnh_(pnh), name_(nodeLogger("qlearning_controller", pnh.getNamespace())), shutdown_(std::move(shutdown))
{
  std::unique_lock<std::mutex> lock(mutex_);
  settings_ = readControllerParameters(nh_, pnh_, shutdown_by_default);
  session_ = std::make_unique<TrainingSession>(settings_.training.task, settings_.training.agent, settings_.run.seed,
                                               settings_.run.learning(), settings_.robots.size());
  if (settings_.run.trace && settings_.run.learning())
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
  if (session_->findingDelay())
    delay_pub_ = pnh_.advertise<std_msgs::UInt32>("found_delay_steps", 1, true);
  if (settings_.run.controlling())
    control_ = std::make_unique<ControlReporter>(
        nh_, settings_.robots, settings_.training.physics.tau, settings_.run.control_max_gap,
        settings_.robot.max_effort, settings_.run.report_every, settings_.training.task.kind,
        settings_.training.physics.rail_limit, [this](const LogLines& log) { say(log); });
  ros::NodeHandle services_nh(pnh_);
  services_nh.setCallbackQueue(&services_queue_);
  save_srv_ = services_nh.advertiseService("save_q_table", &QLearningControllerNode::onSave, this);
  load_srv_ = services_nh.advertiseService("load_q_table", &QLearningControllerNode::onLoad, this);
  services_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &services_queue_);
  services_spinner_->start();
  setUpRobots(state_queue);
  // The watchdog (and the end, endWhenFinished) on the states' queue (a nodelet's: the lockstep
  // thread's, not the manager's), as the executable serves both on one: nodelet 1.10.0 (Debian 11)
  // pauses a nodelet's own queues while it loads and drops what a timer adds meanwhile, after which
  // that timer never fires again (ros/nodelet_core#106, fixed in 1.10.1); the guard would never
  // stop a robot it cannot see.
  timers_nh_ = nh_;
  if (state_queue != nullptr)
    timers_nh_.setCallbackQueue(state_queue);
  watchdog_ = timers_nh_.createSteadyTimer(ros::WallDuration(dispatch_->tickSeconds()),
                                           &QLearningControllerNode::onWatchdog, this);
  std::string served;
  for (const Robot& robot : robots_)
    served += (served.empty() ? "" : ", ") + describe(robot);
  say({{LogLine::Level::Info, controllerStartText(settings_, session_->table(), app_->tableDirectory(), served)}});
  for (const std::string& warning : settings_.warnings)
    say({{LogLine::Level::Warn, warning}});
  lock.unlock();
  startLiveTuning();
}

void QLearningControllerNode::checkParameters(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
{
  const ControllerSettings settings = readControllerParameters(nh, pnh, true);
  TrainingSession session(settings.training.task, settings.training.agent, settings.run.seed, settings.run.learning(),
                          settings.robots.size());
  RunApplication(settings.run, settings.training, session).checkStart();
}

void QLearningControllerNode::setUpRobots(ros::CallbackQueue* state_queue)
{
  robots_.resize(settings_.robots.size());
  std::vector<std::string> names;  // as the log names the robots
  for (std::size_t r = 0; r < robots_.size(); ++r)
  {
    Robot& robot = robots_[r];
    robot.name = settings_.robots[r];
    robot.nh = robot.name.empty() ? nh_ : ros::NodeHandle(nh_, robot.name);
    robot.command = CommandPublisher(robot.nh, settings_.robot.command_topic, settings_.robot);
    if (!robot.name.empty())
      robot.stats_pub = robot.nh.advertise<EpisodeStats>("episode_stats", 100);
    if (settings_.protocol.reset_service)  // docs/nodes.md: the ~reset_service row
      robot.resetter = std::make_unique<ResetCaller>(
          robot.nh.resolveName(settings_.reset_service), settings_.reset_service_type,
          resetGiveUpAfter(settings_.sim_timeout), [this](const LogLines& log) { say(log); });
    ros::NodeHandle state_nh(robot.nh);
    if (state_queue != nullptr)
      state_nh.setCallbackQueue(state_queue);
    // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
    // The event, for its publisher's name: two drivers of one robot are told apart by it.
    robot.state_sub = state_nh.subscribe<sensor_msgs::JointState>(
        settings_.robot.state_topic, 10, StateCallback([this, r](const StateEvent& event) { onJointState(r, event); }),
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    names.push_back(describe(robot));
  }
  const RobotDispatchParams dispatch{
      names,           settings_.sync,     settings_.sim_timeout, settings_.freshness_timeout,
      settings_.robot, settings_.protocol, settings_.simulated,   settings_.run.names};
  dispatch_ = std::make_unique<RobotDispatch>(*session_, dispatch, WallClock::now());
}

QLearningControllerNode::~QLearningControllerNode()
{
  {
    // Set under mutex_ by the callback that ends the run (a nodelet's lockstep thread); its own
    // callback takes no lock.
    const std::lock_guard<std::mutex> lock(mutex_);
    end_timer_.stop();
  }
  // First, with mutex_ free: a reconfigure call or a save under way ends (they take mutex_), no
  // other starts.
  reconfigure_.reset();
  save_srv_.shutdown();  // a call from now on is refused rather than left waiting for the process to end
  load_srv_.shutdown();
  services_spinner_.reset();
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
    std::printf("%s\n", withPrefix(kPrefix, log).c_str());
  for (const LogLine& log : control_ ? control_->summaries() : LogLines())
    std::printf("%s\n", withPrefix(kPrefix, log).c_str());
  // Out now: under roslaunch stdout is a pipe, and a process killed after its slow exit (a
  // loaded machine) would lose what is still buffered (seen in a new Debian 12 root: the line
  // cut after the path).
  std::fflush(stdout);
}

std::string QLearningControllerNode::describe(const Robot& robot) const
{
  return robot.state_sub.getTopic().empty() ? robot.name : robot.state_sub.getTopic();
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

void QLearningControllerNode::onJointState(std::size_t r, const StateEvent& event)
{
  const sensor_msgs::JointStateConstPtr msg = event.getConstMessage();
  const std::string& publisher = event.getPublisherName();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (app_->finished())
    return;
  // A reset's outcome before the state after it: it decides whether that state may start an episode.
  for (const bool succeeded : robots_[r].resetter ? robots_[r].resetter->outcomes() : std::vector<bool>())
    dispatch_->onResetOutcome(r, succeeded);
  const Reading<JointReadings> reading =
      readingsFromJointState(*msg, settings_.robot.cart_joint, settings_.robot.pole_joint);
  if (!reading)
  {
    if (bad_state_warning_.ready())
      say({{LogLine::Level::Warn, reading.refusal}});
    say(dispatch_->onInvalid(r, msg->header.stamp.toNSec(), WallClock::now(), publisher).log);
    return;
  }
  const RobotDispatch::Orders orders =
      dispatch_->onState(r, msg->header.stamp.toNSec(), *reading.value, WallClock::now(), publisher);
  say(orders.log);
  if (orders.hold)
    robots_[r].command.hold(msg->header.stamp, !orders.hold_zero);
  if (!orders.drop && !orders.hold)
    serveDue();
}

void QLearningControllerNode::serveDue()
{
  while (!app_->finished())
  {
    const std::optional<RobotDispatch::Turn> turn = dispatch_->next(WallClock::now());
    if (!turn)
      return;
    serve(*turn);
  }
}

void QLearningControllerNode::serve(const RobotDispatch::Turn& turn)
{
  Robot& robot = robots_[turn.robot];
  const Reaction& reaction = turn.reaction;
  const ros::Time stamp = ros::Time().fromNSec(turn.stamp);
  say(turn.log);
  if (reaction.answer)
    robot.command.publish(reaction.effort, stamp);
  if (reaction.episode_ended && !reaction.answer)
    robot.command.stop();
  if (control_)
    control_->onReaction(turn.robot, reaction, reaction.episode_ended && session_->lastEpisode().terminated,
                         turn.state);
  if (reaction.episode_ended)
    endEpisode(robot, stamp, reaction.training_finished);
  // Reset calls run on threads of their own (ResetCaller): a blocking call from this callback would
  // never return if the sim's service ran on the same single thread (nodelets), and a robot whose
  // call hangs must not hold up the others. None once the destructor has begun.
  if (reaction.request_reset && !app_->finished() && robot.resetter)
    robot.resetter->request();
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
  // Half a second later: the last episode_stats (the solved episode) is still in the publisher's
  // queue, and ending ROS now closes the connections it would leave on (a rostest client saw
  // every episode but the last). States are no longer served meanwhile (app_->finished()).
  end_timer_ = timers_nh_.createSteadyTimer(
      ros::WallDuration(kLingerSeconds),
      [this](const ros::SteadyTimerEvent&) {
        if (endParentLaunch())
          say({{LogLine::Level::Info, "done; ending the launch"}});
        else if (shutdown_)
          shutdown_();
      },
      true);
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
    refuseParameter(pnh_, nodeParameterName(e.setting), e.value, e.why);
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
    say({{LogLine::Level::Info, "ending the launch"}});
}

bool QLearningControllerNode::onSave(SaveQTable::Request& request, SaveQTable::Response& response)
{
  QTable copy = app_->tableOfThisShape();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    app_->copyTableInto(copy);
  }
  say(toResponse(app_->saveCopy(copy, request.path), response));
  return true;
}

bool QLearningControllerNode::onLoad(LoadQTable::Request& request, LoadQTable::Response& response)
{
  TableRead read = app_->readTable(request.path);
  const std::lock_guard<std::mutex> lock(mutex_);
  say(toResponse(app_->useTable(std::move(read)), response));
  return true;
}

void QLearningControllerNode::onWatchdog(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (app_->finished())
    return;
  const RobotDispatch::Orders orders = dispatch_->onTick(WallClock::now());
  for (const std::size_t r : orders.stop)
    robots_[r].command.stop();
  say(orders.log);
  serveDue();
  reportFoundDelay();
}

void QLearningControllerNode::reportFoundDelay()
{
  if (!session_->findingDelay())
    return;
  const std::optional<unsigned> found = session_->foundDelaySteps(0);
  if (!found || found == delay_said_)
    return;
  say({{LogLine::Level::Info,
        formatText("%s carries out each command %u %s late, by how its states answer them: deciding for the state "
                   "predicted %u %s ahead (~predict_delay_steps %u tells it; 0: decide for the state observed)",
                   robots_.front().name.empty() ? "the robot" : robots_.front().name.c_str(), *found,
                   *found == 1 ? "step" : "steps", *found, *found == 1 ? "step" : "steps", *found)}});
  std_msgs::UInt32 msg;
  msg.data = *found;
  delay_pub_.publish(msg);
  delay_said_ = found;
}

void QLearningControllerNode::startLiveTuning()
{
  std::optional<LearningConfig> running;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // A new run starts from its configuration: what an earlier node left on the parameter server
    // is replaced, and said. A respawn finds the values its predecessor served, the live tuning of
    // this run, and goes on with them (onReconfigure says so).
    if (!app_->respawned())
    {
      const LearningSettings& in_use = session_->learningSettings();
      say(liveTuningReplacedLog(learningSettingsLeft(RosParameterSource(pnh_), in_use), in_use));
      running = toConfig(in_use);
    }
  }
  // With mutex_ free: setCallback calls onReconfigure at once, which takes it. The server starts from
  // the parameter server, where a new run first puts the values in use: no client sees others.
  if (running)
    setLearningConfigParams(*running, pnh_);
  // On the services' own queue, as save and load, not the node's: nodelet 1.10.0 (Debian 11)
  // disables a nodelet's queues while its onInit runs and drops what arrives meanwhile
  // (ros/nodelet_core#106, fixed in 1.10.1), so a set_parameters call made during a slow start
  // was never answered and its client waited for ever (live_tuning_nodelet in a Debian 11 root
  // at load 5-9: training had begun on the lockstep thread while the server was still starting).
  ros::NodeHandle reconfigure_nh(pnh_);
  reconfigure_nh.setCallbackQueue(&services_queue_);
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<LearningConfig>>(reconfigure_mutex_, reconfigure_nh);
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
  say(liveTuningLog(in_use, wanted, asServerField(error), first && app_->respawned(), settings_.run.learning()));
}

void QLearningControllerNode::say(const LogLines& log) const
{
  for (const LogLine& line : log)
    logLine(name_, line.level, withPrefix(kPrefix, line));
}

}  // namespace cartpole_qlearning
