#include "cartpole_qlearning/ros/qlearning_controller.h"

#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/ros/launch_control.h"
#include "cartpole_qlearning/q_table_file.h"
#include "cartpole_qlearning/ros/parameter_source.h"

#include <ros/names.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <tuple>
#include <utility>

#include <unistd.h>

namespace cartpole_qlearning
{
namespace
{
// ~robots: a list of namespaces (relative to the learner's), or a whole number N: one robot,
// the learner's own namespace (N = 1), or robot_0 ... robot_<N-1> (train.launch robots:=N).
void readRobots(const ros::NodeHandle& pnh, SectionReader& priv, std::vector<std::string>& names)
{
  priv.know("robots");
  XmlRpc::XmlRpcValue value;
  if (!pnh.getParam("robots", value))
    return;
  const auto refuse = [&](const std::string& why) { refuseParameter(pnh, "robots", "'" + value.toXml() + "'", why); };
  const char* allowed = "a whole number in [1, 1000] or a list of namespaces relative to the controller's";
  if (value.getType() == XmlRpc::XmlRpcValue::TypeInt)
  {
    const int count = static_cast<int>(value);
    if (count < 1 || count > 1000)
      refuse(allowed);
    names.clear();
    if (count == 1)
      names.push_back("");
    for (int i = 0; count > 1 && i < count; ++i)
      names.push_back("robot_" + std::to_string(i));
    return;
  }
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() < 1 || value.size() > 1000)
    refuse(allowed);
  names.clear();
  for (int i = 0; i < value.size(); ++i)
  {
    if (value[i].getType() != XmlRpc::XmlRpcValue::TypeString)
      refuse(allowed);
    const std::string name = static_cast<std::string>(value[i]);
    std::string error;
    if (!name.empty() && !ros::names::validate(name, error))
      refuse("'" + name + "' is not a valid ROS name: " + error);
    if (std::find(names.begin(), names.end(), name) != names.end())
      refuse("'" + name + "' is listed twice");
    names.push_back(name);
  }
}

double secondsSince(std::chrono::steady_clock::time_point then)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - then).count();
}

// The prefix of the node's lines: written here only.
std::string prefixed(const Said& said)
{
  return said.prefixed ? "qlearning_controller: " + said.text : said.text;
}

// Index of a joint by name, or -1.
int jointIndex(const sensor_msgs::JointState& msg, const char* name)
{
  const auto it = std::find(msg.name.begin(), msg.name.end(), name);
  return it == msg.name.end() ? -1 : static_cast<int>(it - msg.name.begin());
}

// Live tuning: the server's fields <-> the core's settings. An override is off when negative.
LearningConfig toConfig(const LearningSettings& s)
{
  LearningConfig c = LearningConfig::__getDefault__();
  c.epsilon_override = s.epsilon_override.value_or(-1.0);
  c.alpha_override = s.alpha_override.value_or(-1.0);
  c.gamma = s.gamma;
  c.epsilon_schedule = toString(s.epsilon.type);
  c.epsilon_start = s.epsilon.start;
  c.epsilon_min = s.epsilon.min;
  c.epsilon_decay_episodes = s.epsilon.decay_episodes;
  c.epsilon_decay_rate = s.epsilon.decay_rate;
  c.epsilon_log_divisor = s.epsilon.log_divisor;
  c.alpha_schedule = toString(s.alpha.type);
  c.alpha_start = s.alpha.start;
  c.alpha_min = s.alpha.min;
  c.alpha_decay_episodes = s.alpha.decay_episodes;
  c.alpha_decay_rate = s.alpha.decay_rate;
  c.alpha_log_divisor = s.alpha.log_divisor;
  return c;
}

// Empty when every field could be read (the values themselves are the core's to check); a
// schedule name the core does not know leaves that schedule's type as it was.
std::string fromConfig(const LearningConfig& c, LearningSettings& s)
{
  const auto rate = [](double value) { return value < 0.0 ? std::nullopt : std::optional<double>(value); };
  s.epsilon_override = rate(c.epsilon_override);
  s.alpha_override = rate(c.alpha_override);
  s.gamma = c.gamma;
  s.epsilon.start = c.epsilon_start;
  s.epsilon.min = c.epsilon_min;
  s.epsilon.decay_episodes = c.epsilon_decay_episodes;
  s.epsilon.decay_rate = c.epsilon_decay_rate;
  s.epsilon.log_divisor = c.epsilon_log_divisor;
  s.alpha.start = c.alpha_start;
  s.alpha.min = c.alpha_min;
  s.alpha.decay_episodes = c.alpha_decay_episodes;
  s.alpha.decay_rate = c.alpha_decay_rate;
  s.alpha.log_divisor = c.alpha_log_divisor;
  const std::tuple<const char*, const std::string&, ScheduleType&> types[] = {
      {"epsilon", c.epsilon_schedule, s.epsilon.type}, {"alpha", c.alpha_schedule, s.alpha.type}};
  for (const auto& [name, text, type] : types)
  {
    try
    {
      type = scheduleTypeFromString(text);
    }
    catch (const std::invalid_argument& e)
    {
      return std::string(name) + "_schedule = '" + text + "' is not allowed (" + e.what() + ")";
    }
  }
  return "";
}

// The core names a schedule's field as the config file does ("epsilon/min"); the server's field
// is "epsilon_min".
std::string asServerField(std::string message)
{
  const std::size_t slash = message.find('/');
  if (slash < message.find(" = "))
    message[slash] = '_';
  return message;
}
}  // namespace

QLearningControllerNode::QLearningControllerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                                 std::function<void()> shutdown, bool shutdown_by_default,
                                                 ros::CallbackQueue* state_queue)
  : nh_(nh), pnh_(pnh), shutdown_(std::move(shutdown)), shutdown_when_finished_(shutdown_by_default)
{
  std::unique_lock<std::mutex> lock(mutex_);
  readParameters();
  session_ = std::make_unique<TrainingSession>(config_.task, config_.agent, seed_, learning_, robot_names_.size());
  if (trace_ && learning_)
  {
    state_names_ = stateNames(config_.agent);
    session_->setTrace([this](std::size_t robot, const TraceStep& step) {
      const std::string& name = robot_names_[robot];
      say({{Said::Level::Info,
            (robot_names_.size() > 1 ? name + ": " : "") + traceLine(step, state_names_, config_.agent.actions),
            false}});
    });
  }
  startRun();
  stats_pub_ = nh_.advertise<EpisodeStats>("episode_stats", 100);
  save_srv_ = pnh_.advertiseService("save_q_table", &QLearningControllerNode::onSave, this);
  load_srv_ = pnh_.advertiseService("load_q_table", &QLearningControllerNode::onLoad, this);
  setUpRobots(state_queue);
  if (protocol_params_.reset_service)
  {
    // README: the ~reset_service row.
    const auto give_up_after = resetGiveUpAfter(sim_timeout_);
    for (Robot& robot : robots_)
      robot.resetter = std::make_unique<ResetCaller>(robot.nh.resolveName(reset_service_), give_up_after);
  }
  watchdog_ = nh_.createSteadyTimer(ros::WallDuration(std::min(0.5, sim_timeout_ / 2.0)),
                                    &QLearningControllerNode::onWatchdog, this);
  std::string served;
  for (const Robot& robot : robots_)
    served += (served.empty() ? "" : ", ") + describe(robot);
  const FeatureParams& features = session_->table().features();
  const std::string rows =
      features.kind == FeatureKind::Tiles
          ? std::to_string(features.tilings) + " tilings, " + std::to_string(session_->table().stateCount()) + " tiles"
          : std::to_string(session_->table().stateCount()) + " states";
  say(Said::Level::Info, "%s, seed %llu, %s x %zu actions, tables under %s; serving %s%s; %s",
      learning_ ? "training" : "evaluating (greedy, no learning)", static_cast<unsigned long long>(seed_), rows.c_str(),
      session_->table().actionCount(), app_->tableDirectory().c_str(), served.c_str(),
      robots_.size() > 1 ? (sync_ ? " in lockstep rounds" : ", each as its states come") : "",
      protocol_params_.reset_service ? ("resets by ~" + reset_service_).c_str()
                                     : "no reset service: episodes start when the state is in ~start_region");
  lock.unlock();
  startLiveTuning();
}

void QLearningControllerNode::setUpRobots(ros::CallbackQueue* state_queue)
{
  rounds_ = std::make_unique<RobotRounds>(
      robot_names_.size(), sync_,
      std::chrono::duration_cast<WallClock::duration>(std::chrono::duration<double>(sim_timeout_)));
  robots_.resize(robot_names_.size());
  const auto now = std::chrono::steady_clock::now();
  for (std::size_t r = 0; r < robots_.size(); ++r)
  {
    Robot& robot = robots_[r];
    robot.name = robot_names_[r];
    ControllerProtocolParams params = protocol_params_;
    params.robot = r;
    robot.protocol = std::make_unique<ControllerProtocol>(*session_, params);
    robot.nh = robot.name.empty() ? nh_ : ros::NodeHandle(nh_, robot.name);
    robot.command_pub = robot.nh.advertise<sensor_msgs::JointState>("joint_command", 10);
    if (!robot.name.empty())
      robot.stats_pub = robot.nh.advertise<EpisodeStats>("episode_stats", 100);
    robot.last_state_at = now;
    ros::NodeHandle state_nh(robot.nh);
    if (state_queue != nullptr)
      state_nh.setCallbackQueue(state_queue);
    // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
    robot.state_sub = state_nh.subscribe<sensor_msgs::JointState>(
        "joint_states", 10, [this, r](const sensor_msgs::JointStateConstPtr& msg) { onJointState(r, msg); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
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
  for (const Said& said : app_ ? app_->shutdown() : Saying())
    std::printf("%s\n", prefixed(said).c_str());
}

void QLearningControllerNode::readParameters()
{
  const RosParameterSource shared(nh_);
  config_ = readTrainingConfig(shared);

  // Private parameters: the same reader and checks as the shared sections; a key it does not
  // know (a typo) stops the node instead of being ignored.
  const RosParameterSource source(pnh_);
  SectionReader priv(source, "");
  // The launch files' stop_when_solved and max_episodes arrive as private parameters; they
  // override the shared training/ keys for this controller only.
  priv.read("stop_when_solved", config_.limits.stop_when_solved);
  priv.read("max_episodes", config_.limits.max_episodes, 1);

  std::string mode = "train";
  priv.readChoice("mode", mode, {"train", "evaluate"});
  learning_ = mode == "train";
  priv.read("seed", seed_, 0);

  q_table_dir_ = defaultTableDirectory(nh_.getNamespace());
  priv.read("q_table_dir", q_table_dir_);
  if (q_table_dir_.empty())
    priv.fail("q_table_dir", "''", "must name a directory");
  // Paths given as "~/..." (roslaunch passes them on unexpanded) name the user's home.
  const char* home = std::getenv("HOME");
  const auto expand_home = [&](const std::string& name, std::string& path) {
    try
    {
      path = expandHome(path, home ? home : "");
    }
    catch (const FileError& e)
    {
      priv.fail(name, "'" + path + "'", e.what());
    }
  };
  expand_home("q_table_dir", q_table_dir_);
  priv.read("q_table_path", q_table_path_);
  expand_home("q_table_path", q_table_path_);
  try
  {
    resolve(q_table_path_);
  }
  catch (const QTableFileError& e)
  {
    priv.fail("q_table_path", "'" + q_table_path_ + "'", e.what());
  }
  priv.read("load_on_start", load_on_start_);
  expand_home("load_on_start", load_on_start_);
  priv.read("stats_csv", stats_csv_);
  expand_home("stats_csv", stats_csv_);
  if (stats_csv_ != "none" && !stats_csv_.empty() && stats_csv_.front() != '/')
  {
    try
    {
      relativePathUnder(q_table_dir_, stats_csv_);
    }
    catch (const FileError& e)
    {
      priv.fail("stats_csv", "'" + stats_csv_ + "'", e.what());
    }
  }
  priv.read("run_id", run_id_);
  // Set by the controller itself (openRun), for a respawn of it to find.
  priv.know("run/id");
  priv.know("run/launcher");
  priv.know("run/folder");
  priv.read("evaluation_episodes", evaluation_episodes_, 0);
  priv.read("checkpoint_every", checkpoint_every_, 0);
  priv.read("save_on_shutdown", save_on_shutdown_);
  priv.read("shutdown_when_finished", shutdown_when_finished_);
  priv.readAtLeast("sim_timeout", sim_timeout_, 0.0, true);
  priv.read("reset_service", reset_service_);
  protocol_params_.reset_service = !reset_service_.empty();
  protocol_params_.start_region = CartPoleState::Constant(config_.start_state_bound);
  std::array<double, kStateDimensions> region{};
  for (std::size_t i = 0; i < kStateDimensions; ++i)
    region[i] = protocol_params_.start_region[i];
  priv.readDimensions("start_region", region, false);
  for (std::size_t i = 0; i < kStateDimensions; ++i)
  {
    if (!(std::isfinite(region[i]) && region[i] > 0.0))
      priv.fail("start_region", SectionReader::listText({region.begin(), region.end()}),
                "must be 4 finite values > 0: |x|, |x_dot|, |theta|, |theta_dot| bounds");
    protocol_params_.start_region[i] = region[i];
  }
  readRobots(pnh_, priv, robot_names_);
  priv.read("sync", sync_);
  priv.read("trace", trace_);
  if (trace_ && config_.agent.features == FeatureKind::Tiles)
    priv.fail("trace", "true", "the trace shows one table row per state: learning/features bins only");
  // Live tuning's values, which the controller's own dynamic_reconfigure server keeps there.
  for (const auto& param : LearningConfig::__getParamDescriptions__())
    priv.know(param->name);
  priv.refuseUnknown();
  protocol_params_.limits = config_.limits;
}

std::string QLearningControllerNode::resolve(const std::string& path) const
{
  return resolvePathUnder(q_table_dir_, path.empty() ? q_table_path_ : path);
}

bool QLearningControllerNode::extractState(const sensor_msgs::JointState& msg, CartPoleState& state) const
{
  const int cart = jointIndex(msg, "cart_joint");
  const int pole = jointIndex(msg, "pole_joint");
  if (cart < 0 || pole < 0)
  {
    if (bad_state_warning_.ready())
      ROS_WARN("qlearning_controller: dropped joint_states without %s", cart < 0 ? "cart_joint" : "pole_joint");
    return false;
  }
  if (msg.position.size() != msg.name.size() || msg.velocity.size() != msg.name.size())
  {
    if (bad_state_warning_.ready())
      ROS_WARN("qlearning_controller: dropped joint_states with %zu names but %zu positions and %zu velocities",
               msg.name.size(), msg.position.size(), msg.velocity.size());
    return false;
  }
  state = CartPoleState(msg.position[cart], msg.velocity[cart], msg.position[pole], msg.velocity[pole]);
  if (!state.allFinite())
  {
    if (bad_state_warning_.ready())
      ROS_WARN("qlearning_controller: dropped joint_states with a non-finite position or velocity");
    return false;
  }
  return true;
}

std::string QLearningControllerNode::describe(const Robot& robot) const
{
  return robot.state_sub.getTopic().empty() ? robot.name : robot.state_sub.getTopic();
}

void QLearningControllerNode::command(Robot& robot, double effort, const ros::Time& stamp)
{
  // A new message each time: in a nodelet manager the sim receives this very pointer.
  auto msg = boost::make_shared<sensor_msgs::JointState>();
  msg->header.stamp = stamp;
  msg->name = {"cart_joint"};
  msg->effort = {effort};
  robot.command_pub.publish(msg);
}

void QLearningControllerNode::onJointState(std::size_t r, const sensor_msgs::JointStateConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  CartPoleState state;
  if (app_->finished() || !extractState(*msg, state))
    return;
  Robot& robot = robots_[r];
  robot.last_state_at = std::chrono::steady_clock::now();
  if (robot.silent_reported)
  {
    robot.silent_reported = false;
    say(Said::Level::Info, "joint_states are back on %s; going on", describe(robot).c_str());
  }
  if (rounds_->heard(r, robot.last_state_at))
    say(Said::Level::Info, "%s takes part in the rounds again", describe(robot).c_str());

  const ros::Time stamp = msg->header.stamp;
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
  if (reaction.episode_ended)
    endEpisode(robot, stamp, reaction.training_finished);
  if (reaction.request_reset && !app_->finished())
    requestReset(r);
}

void QLearningControllerNode::report(const Robot& robot, const Reaction& reaction, const ros::Time& stamp)
{
  const ControllerProtocol::Counts& c = robot.protocol->counts();
  if (reaction.kind == Reaction::Kind::Stale && dropped_state_warning_.ready())
    say(Said::Level::Warn,
        "dropped joint_states on %s stamped %.6f, older than the last state (a replayed or reordered message; a "
        "restarted sim is recognised when it sends its state again). Dropped so far: %llu",
        describe(robot).c_str(), stamp.toSec(), static_cast<unsigned long long>(c.stale));
  if (reaction.kind == Reaction::Kind::Stray && dropped_state_warning_.ready())
    say(Said::Level::Warn, "dropped joint_states on %s without a stamp among stamped ones. Dropped so far: %llu",
        describe(robot).c_str(), static_cast<unsigned long long>(c.stray));
  if (reaction.first_unstamped)
    say(Said::Level::Warn,
        "joint_states on %s carry no stamp (0): every message is taken as a new state, and commands go out "
        "unstamped",
        describe(robot).c_str());
  if (reaction.sim_restarted && restart_warning_.ready())
    say(Said::Level::Warn,
        "%s: time went back to %.3f s: the sim restarted; starting a new episode. Restarts so far: %llu",
        describe(robot).c_str(), stamp.toSec(), static_cast<unsigned long long>(c.restarts));
  if (reaction.waiting_for_start)
    say(Said::Level::Info,
        "%s: episode over; no reset service, so commanding 0 until the state is back inside ~start_region (stand "
        "the pole up)",
        describe(robot).c_str());
}

void QLearningControllerNode::endEpisode(Robot& robot, const ros::Time& stamp, bool training_finished)
{
  // The curve's row, rates, checkpoints and, when training ends here, the final save: before
  // episode_stats says so, so that whoever acts on the last message finds the final file.
  const EpisodeEnd end = app_->endEpisode(robot.name, training_finished);
  if (end.run_folder && !app_->identity().id.empty())
    pnh_.setParam("run/folder", *end.run_folder);
  const EpisodeSummary& s = session_->lastEpisode();

  EpisodeStats stats;
  stats.header.stamp = stamp;
  stats.robot = robot.name;
  stats.episode = static_cast<std::uint32_t>(s.episode);
  stats.steps = s.steps;
  stats.episode_return = s.episode_return;
  stats.mean_return_100 = s.mean_return_window;
  stats.epsilon = s.epsilon;
  stats.alpha = s.alpha;
  stats.gamma = s.gamma;
  stats.terminated = s.terminated;
  stats.truncated = s.truncated;
  stats.solved = s.solved;
  stats.total_steps = s.total_steps;
  stats.steps_per_second = end.steps_per_second;
  stats_pub_.publish(stats);
  if (robot.stats_pub)
  {
    stats.episode = static_cast<std::uint32_t>(s.robot_episode);
    stats.mean_return_100 = s.robot_mean_return_window;
    stats.total_steps = s.robot_total_steps;
    stats.steps_per_second = end.robot_steps_per_second;
    robot.stats_pub.publish(stats);
  }

  say(end.said);
  if (end.finished)
    endWhenFinished();
}

void QLearningControllerNode::endWhenFinished()
{
  if (!shutdown_when_finished_)
    return;
  if (endParentLaunch())
  {
    say(Said::Level::Info, "done; ending the launch");
    return;
  }
  if (shutdown_)
    shutdown_();
}

RunSettings QLearningControllerNode::runSettings() const
{
  RunSettings settings;
  settings.learning = learning_;
  settings.seed = seed_;
  settings.name_space = nh_.getNamespace();
  settings.q_table_dir = q_table_dir_;
  settings.q_table_path = q_table_path_;
  settings.load_on_start = load_on_start_;
  settings.stats_csv = stats_csv_;
  settings.run_id = run_id_;
  settings.evaluation_episodes = evaluation_episodes_;
  settings.checkpoint_every = checkpoint_every_;
  settings.save_on_shutdown = save_on_shutdown_;
  settings.trace = trace_;
  return settings;
}

void QLearningControllerNode::startRun()
{
  app_ = std::make_unique<RunApplication>(runSettings(), config_, *session_);
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
  if (app_->finished() && shutdown_when_finished_ && endParentLaunch())
    say(Said::Level::Info, "ending the launch");
}

bool QLearningControllerNode::onSave(SaveQTable::Request& request, SaveQTable::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const ServiceAnswer answer = app_->save(request.path);
  response.success = answer.success;
  response.message = answer.message;
  say(answer.said);
  return true;
}

bool QLearningControllerNode::onLoad(LoadQTable::Request& request, LoadQTable::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const ServiceAnswer answer = app_->load(request.path);
  response.success = answer.success;
  response.message = answer.message;
  say(answer.said);
  return true;
}

void QLearningControllerNode::onWatchdog(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (app_->finished())
    return;
  for (Robot& robot : robots_)
  {
    if (robot.silent_reported || secondsSince(robot.last_state_at) < sim_timeout_)
      continue;
    robot.silent_reported = true;
    say(Said::Level::Warn, "no joint_states on %s for %.1f s: is its cartpole_sim running? Waiting for it",
        describe(robot).c_str(), sim_timeout_);
  }
  const std::vector<std::size_t> dropped = rounds_->dropOuts(WallClock::now());
  for (const std::size_t r : dropped)
    say(Said::Level::Warn, "%s is silent; the rounds go on without it until it is back", describe(robots_[r]).c_str());
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
      const std::string replaced = learningChangesText(left_settings, running);
      if (!replaced.empty())
        say(Said::Level::Info,
            "a new run: live-tuning values left on the parameter server replaced by its configuration's: %s",
            replaced.c_str());
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
  if (!error.empty())
  {
    if (first && app_->respawned())
      say(Said::Level::Warn,
          "restarted; the live tuning left by the controller before the restart is refused (%s): this run goes on "
          "with its configuration's: %s",
          asServerField(error).c_str(), learningSettingsText(in_use).c_str());
    else
      say(Said::Level::Warn, "live tuning refused (asked: %s): %s; nothing changed, in use: %s",
          learningChangesText(in_use, wanted).c_str(), asServerField(error).c_str(),
          learningSettingsText(in_use).c_str());
    return;
  }
  const std::string changes = learningChangesText(in_use, wanted);
  if (changes.empty())
    return;
  const char* applies = learning_ ? "gamma from the next update, epsilon and alpha from the next episode"
                                  : "evaluating, so none of it applies: actions stay greedy (epsilon 0), nothing "
                                    "is learnt (alpha 0, gamma unused)";
  if (first && app_->respawned())
    say(Said::Level::Warn, "restarted; the live tuning of this run before the restart applies again: %s (%s)",
        changes.c_str(), applies);
  else
    say(Said::Level::Info, "live tuning: %s (%s)", changes.c_str(), applies);
}

void QLearningControllerNode::requestReset(std::size_t robot)
{
  // None once the destructor has begun.
  if (robots_.at(robot).resetter)
    robots_.at(robot).resetter->request();
}

void QLearningControllerNode::say(const Saying& said) const
{
  for (const Said& line : said)
  {
    switch (line.level)
    {
      case Said::Level::Info:
        ROS_INFO_STREAM_NAMED("qlearning_controller", prefixed(line));
        break;
      case Said::Level::Warn:
        ROS_WARN_STREAM_NAMED("qlearning_controller", prefixed(line));
        break;
      case Said::Level::Error:
        ROS_ERROR_STREAM_NAMED("qlearning_controller", prefixed(line));
        break;
    }
  }
}

void QLearningControllerNode::say(Said::Level level, const char* format, ...) const
{
  std::va_list args;
  va_start(args, format);
  std::va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size > 0)
    std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  say({{level, text}});
}

}  // namespace cartpole_qlearning
