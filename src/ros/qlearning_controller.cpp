#include "cartpole_qlearning/ros/qlearning_controller.h"

#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/ros/launch_control.h"
#include "cartpole_qlearning/q_table_file.h"
#include "cartpole_qlearning/ros/parameter_source.h"

#include <ros/names.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <ctime>
#include <sstream>
#include <tuple>
#include <utility>

#include <unistd.h>

namespace cartpole_qlearning
{
namespace
{
// [s] A reset call is given up after max(this, 2 x ~sim_timeout) (README: the ~reset_service row).
constexpr double kMinResetGiveUp = 5.0;
constexpr double kMaxResetGiveUp = 3600.0;

double secondsSince(std::chrono::steady_clock::time_point then)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - then).count();
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
      ROS_INFO("%s%s", settings_.robots.size() > 1 ? (name + ": ").c_str() : "",
               traceLine(step, state_names_, settings_.training.agent.actions).c_str());
    });
  }
  if (!settings_.run.load_on_start.empty())
  {
    std::string path;
    try
    {
      path = resolve(settings_.run.load_on_start);
      const std::string mismatch = install(loadQTableUnder(settings_.run.q_table_dir, settings_.run.load_on_start));
      if (!mismatch.empty())
        throw QTableFileError(path + " does not fit this controller: " + mismatch);
    }
    catch (const QTableFileError& e)
    {
      throw ConfigError("cannot start from the table '" + settings_.run.load_on_start +
                        "' (~load_on_start, which the launch files' q_table or load argument sets): " + e.what());
    }
    ROS_INFO("qlearning_controller: loaded %s (%llu episodes, %llu steps of training)", path.c_str(),
             static_cast<unsigned long long>(session_->table().episodes),
             static_cast<unsigned long long>(session_->table().steps));
  }
  else if (!settings_.run.learning)
  {
    ROS_WARN("qlearning_controller: evaluating a table of zeros (set ~load_on_start to a trained table)");
  }
  openStatsFile();
  if (settings_.run.learning)
    openRun();
  startStatsCsv();

  started_ = last_episode_end_ = last_progress_ = std::chrono::steady_clock::now();
  stats_pub_ = nh_.advertise<EpisodeStats>("episode_stats", 100);
  save_srv_ = pnh_.advertiseService("save_q_table", &QLearningControllerNode::onSave, this);
  load_srv_ = pnh_.advertiseService("load_q_table", &QLearningControllerNode::onLoad, this);
  setUpRobots(state_queue);
  if (settings_.protocol.reset_service)
  {
    // Long enough for a sim that is merely slow (loaded, or far away) to answer, since giving a
    // call up leaves a thread and a connection behind; ~sim_timeout is how long the user lets a
    // sim be silent before calling it gone.
    // (At most an hour: a huge ~sim_timeout must not overflow the clock's arithmetic.)
    const auto give_up_after =
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(
            std::min(kMaxResetGiveUp, std::max(kMinResetGiveUp, 2.0 * settings_.sim_timeout))));
    for (Robot& robot : robots_)
      robot.resetter = std::make_unique<ResetCaller>(robot.nh.resolveName(settings_.reset_service), give_up_after);
  }
  watchdog_ = nh_.createSteadyTimer(ros::WallDuration(std::min(0.5, settings_.sim_timeout / 2.0)),
                                    &QLearningControllerNode::onWatchdog, this);
  std::string served;
  for (const Robot& robot : robots_)
    served += (served.empty() ? "" : ", ") + describe(robot);
  const FeatureParams& features = session_->table().features();
  const std::string rows =
      features.kind == FeatureKind::Tiles
          ? std::to_string(features.tilings) + " tilings, " + std::to_string(session_->table().stateCount()) + " tiles"
          : std::to_string(session_->table().stateCount()) + " states";
  ROS_INFO("qlearning_controller: %s, seed %llu, %s x %zu actions, tables under %s; serving %s%s; %s",
           settings_.run.learning ? "training" : "evaluating (greedy, no learning)",
           static_cast<unsigned long long>(settings_.run.seed), rows.c_str(), session_->table().actionCount(),
           settings_.run.q_table_dir.c_str(), served.c_str(),
           robots_.size() > 1 ? (settings_.sync ? " in lockstep rounds" : ", each as its states come") : "",
           settings_.protocol.reset_service ? ("resets by ~" + settings_.reset_service).c_str()
                                            : "no reset service: episodes start when the state is in ~start_region");
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
    robot.command_pub = robot.nh.advertise<sensor_msgs::JointState>("joint_command", 10);
    if (!robot.name.empty())
      robot.stats_pub = robot.nh.advertise<EpisodeStats>("episode_stats", 100);
    robot.last_state_at = robot.last_episode_end = now;
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
  if (settings_.run.learning && settings_.run.save_on_shutdown && !final_saved_)
  {
    std::string message;
    checkpoint("", message);
    // ROS may be shut down already: say it on the console too.
    std::printf("qlearning_controller: on shutdown: %s (the default table is left as it was)\n", message.c_str());
  }
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
  settings_ = readControllerSettings(RosParameterSource(nh_), RosParameterSource(pnh_), context);
}

std::string QLearningControllerNode::resolve(const std::string& path) const
{
  return resolvePathUnder(settings_.run.q_table_dir, path.empty() ? settings_.run.q_table_path : path);
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
  if (finished_training_ || !extractState(*msg, state))
    return;
  Robot& robot = robots_[r];
  robot.last_state_at = std::chrono::steady_clock::now();
  if (robot.silent_reported)
  {
    robot.silent_reported = false;
    ROS_INFO("qlearning_controller: joint_states are back on %s; going on", describe(robot).c_str());
  }
  if (rounds_->heard(r, robot.last_state_at))
    ROS_INFO("qlearning_controller: %s takes part in the rounds again", describe(robot).c_str());

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
  while (!finished_training_ && rounds_->roundComplete())
  {
    for (std::size_t r = 0; r < robots_.size() && !finished_training_; ++r)
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
  if (reaction.request_reset && !finished_training_)
    requestReset(r);
}

void QLearningControllerNode::report(const Robot& robot, const Reaction& reaction, const ros::Time& stamp)
{
  const ControllerProtocol::Counts& c = robot.protocol->counts();
  if (reaction.kind == Reaction::Kind::Stale && dropped_state_warning_.ready())
    ROS_WARN(
        "qlearning_controller: dropped joint_states on %s stamped %.6f, older than the last state (a replayed or "
        "reordered message; a restarted sim is recognised when it sends its state again). Dropped so far: %llu",
        describe(robot).c_str(), stamp.toSec(), static_cast<unsigned long long>(c.stale));
  if (reaction.kind == Reaction::Kind::Stray && dropped_state_warning_.ready())
    ROS_WARN(
        "qlearning_controller: dropped joint_states on %s without a stamp among stamped ones. Dropped so far: %llu",
        describe(robot).c_str(), static_cast<unsigned long long>(c.stray));
  if (reaction.first_unstamped)
    ROS_WARN(
        "qlearning_controller: joint_states on %s carry no stamp (0): every message is taken as a new state, and "
        "commands go out unstamped",
        describe(robot).c_str());
  if (reaction.sim_restarted && restart_warning_.ready())
    ROS_WARN(
        "qlearning_controller: %s: time went back to %.3f s: the sim restarted; starting a new episode. Restarts so "
        "far: %llu",
        describe(robot).c_str(), stamp.toSec(), static_cast<unsigned long long>(c.restarts));
  if (reaction.waiting_for_start)
    ROS_INFO(
        "qlearning_controller: %s: episode over; no reset service, so commanding 0 until the state is back inside "
        "~start_region (stand the pole up)",
        describe(robot).c_str());
}

void QLearningControllerNode::endEpisode(Robot& robot, const ros::Time& stamp, bool training_finished)
{
  const EpisodeSummary& s = session_->lastEpisode();
  // Before any checkpoint: a row is never missing from a run that a respawn resumes from there.
  writeStatsRow(robot, s);
  const double wall = secondsSince(last_episode_end_);
  const double robot_wall = secondsSince(robot.last_episode_end);
  last_episode_end_ = robot.last_episode_end = std::chrono::steady_clock::now();

  // When training ends here, the table is saved before episode_stats says so: whoever acts on
  // the last message finds the final file. Into the run's folder; a solved run also replaces the
  // default table (the one evaluate.launch loads), an unsolved one leaves it as it was.
  std::string saved;
  bool saved_ok = true;
  if (training_finished)
  {
    // The default table first: a crash between the two saves then leaves a run not yet marked
    // finished, which a respawn finishes again.
    std::string published;
    const bool published_ok = s.solved && save("", published);
    saved_ok = checkpoint(s.solved ? "solved" : "max_episodes", saved);
    final_saved_ = saved_ok || published_ok;
    if (s.solved)
      saved += published_ok ? "; the default table: " + published : "; BUT NOT the default table: " + published;
    else
      saved += "; the default table " + resolve("") +
               " is left as it was (this run did not solve: ~save_q_table saves it there if you want it)";
  }

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
  stats.steps_per_second = wall > 0.0 ? (s.total_steps - steps_at_last_episode_) / wall : 0.0;
  steps_at_last_episode_ = s.total_steps;
  stats_pub_.publish(stats);
  if (robot.stats_pub)
  {
    stats.episode = static_cast<std::uint32_t>(s.robot_episode);
    stats.mean_return_100 = s.robot_mean_return_window;
    stats.total_steps = s.robot_total_steps;
    stats.steps_per_second = robot_wall > 0.0 ? s.steps / robot_wall : 0.0;
    robot.stats_pub.publish(stats);
  }

  if (settings_.run.trace && settings_.run.learning)
  {
    const std::string which = robots_.size() > 1 ? robot.name + "'s episode " + std::to_string(s.robot_episode) + " (" +
                                                       std::to_string(s.episode) + " in all)"
                                                 : "episode " + std::to_string(s.episode);
    ROS_INFO("Q-table after %s:\n%s", which.c_str(), qTableText(session_->table(), state_names_).c_str());
  }

  const TrainingLimits& limits = settings_.training.limits;
  if (limits.progress_every > 0 && s.episode % limits.progress_every == 0)
  {
    const double interval = secondsSince(last_progress_);
    const double rate = interval > 0.0 ? (s.total_steps - steps_at_last_progress_) / interval : 0.0;
    ROS_INFO("%s", progressLine(s, settings_.training.task.solved_window, rate, secondsSince(started_)).c_str());
    steps_at_last_progress_ = s.total_steps;
    last_progress_ = std::chrono::steady_clock::now();
  }

  if (!settings_.run.learning)
  {
    // Evaluation: every episode said, and after ~evaluation_episodes a one-line verdict.
    evaluated_balanced_ += s.truncated && !s.terminated;
    ROS_INFO("qlearning_controller: evaluation episode %llu: %u steps, return %.1f, %s",
             static_cast<unsigned long long>(s.episode), s.steps, s.episode_return,
             s.terminated ? "fell" : "balanced to the step limit");
    if (settings_.run.evaluation_episodes == 0 || s.episode < settings_.run.evaluation_episodes)
      return;
    ROS_INFO(
        "qlearning_controller: EVALUATED %llu episodes: %llu balanced to the step limit (%u steps), mean return %.1f",
        static_cast<unsigned long long>(s.episode), static_cast<unsigned long long>(evaluated_balanced_),
        settings_.training.task.max_episode_steps, s.mean_return_window);
    finished_training_ = true;
    endWhenFinished();
    return;
  }
  if (training_finished)
  {
    finished_training_ = true;
    if (!saved_ok)
    {
      // Keep the trained table alive: the user can still save it elsewhere with ~save_q_table.
      ROS_ERROR(
          "qlearning_controller: training ended (%s, episode %llu) but the table could not be saved: %s. "
          "The node keeps running: call ~save_q_table with another path",
          s.solved ? "solved" : "max_episodes", static_cast<unsigned long long>(s.episode), saved.c_str());
      return;
    }
    ROS_INFO("qlearning_controller: %s after %llu episodes, %llu steps, %.1f s (mean return of the last %u: %.2f); %s",
             s.solved ? "SOLVED" : "NOT solved, max_episodes reached", static_cast<unsigned long long>(s.episode),
             static_cast<unsigned long long>(s.total_steps), secondsSince(started_),
             settings_.training.task.solved_window, s.mean_return_window, saved.c_str());
    endWhenFinished();
    return;
  }
  if (settings_.run.checkpoint_every > 0 && s.episode % settings_.run.checkpoint_every == 0)
  {
    std::string message;
    if (checkpoint("", message))
      ROS_INFO("qlearning_controller: checkpoint: %s", message.c_str());
    else
      ROS_WARN("qlearning_controller: checkpoint failed: %s", message.c_str());
  }
}

std::string QLearningControllerNode::install(QTable table)
{
  // Training goes on with the table's own counts: episode numbers, steps, the schedules and
  // max_episodes all count from them, so the progress lines and the saves agree. (The solved
  // window starts empty.) Evaluation counts its own episodes from 1.
  const std::string mismatch =
      settings_.run.learning ? session_->resume(std::move(table), {}) : session_->replaceTable(std::move(table));
  // Steps per second count from here.
  steps_at_last_episode_ = steps_at_last_progress_ = session_->lastEpisode().total_steps;
  return mismatch;
}

void QLearningControllerNode::endWhenFinished()
{
  if (!settings_.shutdown_when_finished)
    return;
  if (endParentLaunch())
  {
    ROS_INFO("qlearning_controller: done; ending the launch");
    return;
  }
  if (shutdown_)
    shutdown_();
}

void QLearningControllerNode::openRun()
{
  run_.run_id = settings_.run.run_id;
  run_.name_space = nh_.getNamespace();
  run_.seed = settings_.run.seed;
  // A respawn has the run id and the roslaunch (else the parent) of the process that started the
  // run; a node started by hand on a reused master has at most the id left there.
  const pid_t roslaunch = launchingRoslaunch();
  const int launcher = static_cast<int>(roslaunch > 0 ? roslaunch : ::getppid());
  std::string stored_id;
  int stored_launcher = 0;
  if (!settings_.run.run_id.empty() && pnh_.getParam("run/id", stored_id) && stored_id == settings_.run.run_id &&
      pnh_.getParam("run/launcher", stored_launcher) && stored_launcher == launcher &&
      pnh_.getParam("run/folder", run_folder_) && !run_folder_.empty())
  {
    respawned_ = true;
    resumeRun();
    return;
  }
  const std::time_t now = std::time(nullptr);
  run_.started = localTimeText(now);
  const std::string name = runFolderName(now, nh_.getNamespace(), settings_.run.seed);
  // Made now, so that a folder that cannot be written is said at the start, not at the first
  // checkpoint; a name taken (another run started in the same second) gets a suffix. A node told
  // to write nothing along the way (no checkpoints, no save on shutdown) writes nothing yet.
  run_folder_ = name;
  try
  {
    for (int n = 2; (settings_.run.checkpoint_every > 0 || settings_.run.save_on_shutdown) &&
                    !makeDirectoryUnder(settings_.run.q_table_dir, run_folder_);
         ++n)
      run_folder_ = name + "_" + std::to_string(n);
    if (settings_.run.checkpoint_every > 0 || settings_.run.save_on_shutdown)
      writeFileUnder(settings_.run.q_table_dir, run_folder_ + "/" + kRunRecordFile, formatRunRecord(run_));
  }
  catch (const FileError& e)
  {
    ROS_ERROR(
        "qlearning_controller: cannot make this run's folder (%s): checkpoints will fail; ~save_q_table can "
        "still save the table elsewhere",
        e.what());
  }
  if (!settings_.run.run_id.empty())
  {
    pnh_.setParam("run/id", settings_.run.run_id);
    pnh_.setParam("run/launcher", launcher);
    pnh_.setParam("run/folder", run_folder_);
  }
  ROS_INFO("qlearning_controller: run %s: checkpoints go to %s", run_folder_.c_str(),
           resolve(run_folder_ + "/" + kRunTableFile).c_str());
}

void QLearningControllerNode::openStatsFile()
{
  if (settings_.run.stats_csv == "none" || settings_.run.stats_csv.empty())
    return;
  try
  {
    stats_file_ = std::make_unique<AppendingFile>(
        settings_.run.stats_csv.front() == '/'
            ? AppendingFile::open(settings_.run.stats_csv)
            : AppendingFile::openUnder(settings_.run.q_table_dir, settings_.run.stats_csv));
  }
  catch (const FileError& e)
  {
    refuseParameter(pnh_, "stats_csv", "'" + settings_.run.stats_csv + "'", e.what());
  }
}

void QLearningControllerNode::startStatsCsv()
{
  if (settings_.run.stats_csv == "none" || (settings_.run.stats_csv.empty() && !settings_.run.learning))
    return;
  if (!stats_file_)
  {
    // The run's own file: beside its checkpoints, made with its folder. A node told to write
    // nothing along the way (no checkpoints, no save on shutdown) makes that folder only when
    // there is something to write: here, at the first episode's end.
    if (!(settings_.run.checkpoint_every > 0 || settings_.run.save_on_shutdown) && !resumed_run_ && !stats_csv_pending_)
    {
      stats_csv_pending_ = true;
      return;
    }
    try
    {
      if (stats_csv_pending_)
      {
        // Its folder is made now, under a name no other run has taken (as openRun does).
        const std::string name = run_folder_;
        for (int n = 2; !makeDirectoryUnder(settings_.run.q_table_dir, run_folder_); ++n)
          run_folder_ = name + "_" + std::to_string(n);
        if (!settings_.run.run_id.empty())
          pnh_.setParam("run/folder", run_folder_);
      }
      stats_csv_pending_ = false;
      stats_file_ = std::make_unique<AppendingFile>(
          AppendingFile::openUnder(settings_.run.q_table_dir, run_folder_ + "/" + kRunEpisodesFile));
    }
    catch (const FileError& e)
    {
      stats_csv_pending_ = false;
      ROS_ERROR("qlearning_controller: no learning curve for this run (~stats_csv none silences this): %s", e.what());
      return;
    }
  }
  try
  {
    // A respawn goes on with its run's curve from the checkpoint it resumed (a run that starts
    // over keeps the header alone); anything else starts the curve afresh.
    stats_csv_writer_ = resumed_run_
                            ? std::make_unique<EpisodeCsvWriter>(std::move(*stats_file_), session_->episodesEnded())
                            : std::make_unique<EpisodeCsvWriter>(std::move(*stats_file_));
  }
  catch (const FileError& e)
  {
    stats_file_.reset();
    if (!settings_.run.stats_csv.empty())
      refuseParameter(pnh_, "stats_csv", "'" + settings_.run.stats_csv + "'", e.what());
    ROS_ERROR("qlearning_controller: no learning curve for this run (~stats_csv none silences this): %s", e.what());
    return;
  }
  stats_file_.reset();
  ROS_INFO(
      "qlearning_controller: one row per episode goes to %s (rosrun cartpole_qlearning plot_learning_curve "
      "--follow %s)",
      stats_csv_writer_->path().c_str(), stats_csv_writer_->path().c_str());
}

void QLearningControllerNode::writeStatsRow(const Robot& robot, const EpisodeSummary& summary)
{
  if (stats_csv_pending_)
    startStatsCsv();
  if (!stats_csv_writer_)
    return;
  try
  {
    stats_csv_writer_->write(summary, robot.name, ros::WallTime::now().toSec());
  }
  catch (const FileError& e)
  {
    ROS_ERROR("qlearning_controller: the learning curve stops here: %s", e.what());
    stats_csv_writer_.reset();
  }
}

void QLearningControllerNode::resumeRun()
{
  resumed_run_ = true;
  const std::string table_path = run_folder_ + "/" + kRunTableFile;
  RunRecord record;
  QTable table;
  try
  {
    record = parseRunRecord(readFileUnder(settings_.run.q_table_dir, run_folder_ + "/" + kRunRecordFile, 1 << 20));
    table = loadQTableUnder(settings_.run.q_table_dir, table_path);
  }
  catch (const FileError& e)
  {
    // Killed before its first checkpoint (or the checkpoint is unusable): the run starts over.
    run_.started = localTimeText(std::time(nullptr));
    ROS_WARN("qlearning_controller: restarted; run %s has no checkpoint to go on from (%s): starting it over",
             run_folder_.c_str(), e.what());
    return;
  }
  // A crash between the table's save and the record's leaves the record one checkpoint behind:
  // the table wins, and the solved window starts empty.
  const bool record_matches = record.episodes == table.episodes && record.steps == table.steps;
  const std::string mismatch =
      session_->resume(std::move(table), record_matches ? record.recent_returns : std::vector<double>());
  if (!mismatch.empty())
    throw ConfigError("restarted, but the checkpoint " + resolve(table_path) +
                      " does not fit this controller's configuration: " + mismatch);
  run_ = record;
  const EpisodeSummary& s = session_->lastEpisode();
  steps_at_last_episode_ = steps_at_last_progress_ = s.total_steps;
  ROS_WARN("qlearning_controller: restarted; run %s goes on from its checkpoint: episode %llu, %llu steps%s",
           run_folder_.c_str(), static_cast<unsigned long long>(s.episode),
           static_cast<unsigned long long>(s.total_steps),
           record_matches ? "" : " (its record was one checkpoint behind: the solved window starts empty)");
  if (!record.finished.empty())
  {
    // Ended (or killed) after its final save: nothing to train. It stays up rather than exit,
    // which under respawn would only start it again.
    finished_training_ = final_saved_ = true;
    ROS_INFO("qlearning_controller: run %s has finished already (%s); nothing left to do", run_folder_.c_str(),
             record.finished.c_str());
    if (settings_.shutdown_when_finished && endParentLaunch())
      ROS_INFO("qlearning_controller: ending the launch");
  }
}

bool QLearningControllerNode::checkpoint(const std::string& finished, std::string& message)
{
  if (!save(run_folder_ + "/" + kRunTableFile, message))
    return false;
  run_.episodes = session_->table().episodes;
  run_.steps = session_->table().steps;
  run_.recent_returns = session_->recentReturns();
  run_.finished = finished;
  try
  {
    writeFileUnder(settings_.run.q_table_dir, run_folder_ + "/" + kRunRecordFile, formatRunRecord(run_));
  }
  catch (const std::exception& e)
  {
    message +=
        ", but not its run record (a restart would go on from the previous checkpoint): " + std::string(e.what());
    return false;
  }
  return true;
}

bool QLearningControllerNode::save(const std::string& path, std::string& message)
{
  try
  {
    const std::string resolved = resolve(path);
    saveQTableUnder(session_->table(), settings_.run.q_table_dir, path.empty() ? settings_.run.q_table_path : path);
    message = "saved " + std::to_string(session_->table().episodes) + " episodes, " +
              std::to_string(session_->table().steps) + " steps of training to " + resolved;
    return true;
  }
  catch (const std::exception& e)  // QTableFileError, or anything else: never out of a service
  {
    message = std::string("nothing written: ") + e.what();
    return false;
  }
}

bool QLearningControllerNode::onSave(SaveQTable::Request& request, SaveQTable::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  response.success = save(request.path, response.message);
  if (response.success)
    ROS_INFO("qlearning_controller: save_q_table: %s", response.message.c_str());
  else
    ROS_WARN("qlearning_controller: save_q_table: %s", response.message.c_str());
  return true;
}

bool QLearningControllerNode::onLoad(LoadQTable::Request& request, LoadQTable::Response& response)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  try
  {
    const std::string path = resolve(request.path);
    QTable table =
        loadQTableUnder(settings_.run.q_table_dir, request.path.empty() ? settings_.run.q_table_path : request.path);
    const std::uint64_t episodes = table.episodes;
    const std::uint64_t steps = table.steps;
    const std::string mismatch = install(std::move(table));
    if (!mismatch.empty())
      throw QTableFileError(path + " does not fit this controller: " + mismatch);
    response.success = true;
    response.message = "loaded " + path + " (" + std::to_string(episodes) + " episodes, " + std::to_string(steps) +
                       " steps of training)";
    ROS_INFO("qlearning_controller: load_q_table: %s", response.message.c_str());
    if (settings_.run.learning && stats_csv_writer_)
    {
      // Training goes on from the loaded table's episode count; the curve follows it.
      try
      {
        stats_csv_writer_->startOver();
        ROS_INFO("qlearning_controller: the learning curve %s starts over from the loaded table's episode %llu",
                 stats_csv_writer_->path().c_str(), static_cast<unsigned long long>(episodes));
      }
      catch (const FileError& e)
      {
        ROS_WARN("qlearning_controller: %s; the learning curve stops here", e.what());
        stats_csv_writer_.reset();
      }
    }
  }
  catch (const std::exception& e)  // QTableFileError, or anything else: never out of a service
  {
    response.success = false;
    response.message = std::string("refused, the table in use is unchanged: ") + e.what();
    ROS_WARN("qlearning_controller: load_q_table: %s", response.message.c_str());
  }
  return true;
}

void QLearningControllerNode::onWatchdog(const ros::SteadyTimerEvent&)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (finished_training_)
    return;
  for (Robot& robot : robots_)
  {
    if (robot.silent_reported || secondsSince(robot.last_state_at) < settings_.sim_timeout)
      continue;
    robot.silent_reported = true;
    ROS_WARN("qlearning_controller: no joint_states on %s for %.1f s: is its cartpole_sim running? Waiting for it",
             describe(robot).c_str(), settings_.sim_timeout);
  }
  const std::vector<std::size_t> dropped = rounds_->dropOuts(WallClock::now());
  for (const std::size_t r : dropped)
    ROS_WARN("qlearning_controller: %s is silent; the rounds go on without it until it is back",
             describe(robots_[r]).c_str());
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
    if (!respawned_)
    {
      const LearningSettings& running = session_->learningSettings();
      LearningConfig left = toConfig(running);
      left.__fromServer__(pnh_);  // only the fields present there change
      LearningSettings left_settings = running;
      fromConfig(left, left_settings);
      const std::string replaced = learningChangesText(left_settings, running);
      if (!replaced.empty())
        ROS_INFO(
            "qlearning_controller: a new run: live-tuning values left on the parameter server replaced by "
            "its configuration's: %s",
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
    if (first && respawned_)
      ROS_WARN(
          "qlearning_controller: restarted; the live tuning left by the controller before the restart is refused "
          "(%s): this run goes on with its configuration's: %s",
          asServerField(error).c_str(), learningSettingsText(in_use).c_str());
    else
      ROS_WARN("qlearning_controller: live tuning refused (asked: %s): %s; nothing changed, in use: %s",
               learningChangesText(in_use, wanted).c_str(), asServerField(error).c_str(),
               learningSettingsText(in_use).c_str());
    return;
  }
  const std::string changes = learningChangesText(in_use, wanted);
  if (changes.empty())
    return;
  const char* applies = settings_.run.learning
                            ? "gamma from the next update, epsilon and alpha from the next episode"
                            : "evaluating, so none of it applies: actions stay greedy (epsilon 0), nothing "
                              "is learnt (alpha 0, gamma unused)";
  if (first && respawned_)
    ROS_WARN("qlearning_controller: restarted; the live tuning of this run before the restart applies again: %s (%s)",
             changes.c_str(), applies);
  else
    ROS_INFO("qlearning_controller: live tuning: %s (%s)", changes.c_str(), applies);
}

void QLearningControllerNode::requestReset(std::size_t robot)
{
  // None once the destructor has begun.
  if (robots_.at(robot).resetter)
    robots_.at(robot).resetter->request();
}

}  // namespace cartpole_qlearning
