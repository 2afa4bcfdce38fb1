#include "cartpole_qlearning/qlearning_controller_node.h"

#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/q_table_file.h"
#include "cartpole_qlearning/ros_parameter_source.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
std::string defaultTableDirectory()
{
  const char* ros_home = std::getenv("ROS_HOME");
  if (ros_home != nullptr && *ros_home != '\0')
    return std::string(ros_home) + "/cartpole_qlearning";
  const char* home = std::getenv("HOME");
  return std::string(home != nullptr ? home : ".") + "/.ros/cartpole_qlearning";
}

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
}  // namespace

QLearningControllerNode::QLearningControllerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                                 std::function<void()> shutdown, bool shutdown_by_default,
                                                 ros::CallbackQueue* state_queue)
  : nh_(nh), pnh_(pnh), shutdown_(std::move(shutdown)), shutdown_when_finished_(shutdown_by_default)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  readParameters();
  session_ = std::make_unique<TrainingSession>(config_.task, config_.agent, seed_, learning_);
  protocol_ = std::make_unique<ControllerProtocol>(*session_, protocol_params_);
  if (!load_on_start_.empty())
  {
    std::string path;
    try
    {
      path = resolve(load_on_start_);
      const std::string mismatch = session_->replaceTable(loadQTableFile(path));
      if (!mismatch.empty())
        throw QTableFileError(path + " does not fit this controller: " + mismatch);
    }
    catch (const QTableFileError& e)
    {
      refuseParameter(pnh_, "load_on_start", "'" + load_on_start_ + "'", e.what());
    }
    ROS_INFO("qlearning_controller: loaded %s (%llu episodes, %llu steps of training)", path.c_str(),
             static_cast<unsigned long long>(session_->table().episodes),
             static_cast<unsigned long long>(session_->table().steps));
  }
  else if (!learning_)
  {
    ROS_WARN("qlearning_controller: evaluating a table of zeros (set ~load_on_start to a trained table)");
  }

  started_ = last_episode_end_ = last_state_at_ = last_progress_ = std::chrono::steady_clock::now();
  command_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_command", 10);
  stats_pub_ = nh_.advertise<EpisodeStats>("episode_stats", 100);
  save_srv_ = pnh_.advertiseService("save_q_table", &QLearningControllerNode::onSave, this);
  load_srv_ = pnh_.advertiseService("load_q_table", &QLearningControllerNode::onLoad, this);
  if (protocol_params_.reset_service)
  {
    // Persistent: a new connection per episode would cost a master lookup and a TCP set-up.
    reset_client_ = nh_.serviceClient<Reset>(reset_service_, true);
    reset_thread_ = std::thread(&QLearningControllerNode::resetLoop, this);
  }
  watchdog_ = nh_.createSteadyTimer(ros::WallDuration(std::min(0.5, sim_timeout_ / 2.0)),
                                    &QLearningControllerNode::onWatchdog, this);
  // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
  ros::NodeHandle state_nh(nh_);
  if (state_queue != nullptr)
    state_nh.setCallbackQueue(state_queue);
  joint_state_sub_ = state_nh.subscribe("joint_states", 10, &QLearningControllerNode::onJointState, this,
                                        ros::TransportHints().tcpNoDelay());
  ROS_INFO("qlearning_controller: %s, seed %llu, %zu states x %zu actions, tables under %s, %s",
           learning_ ? "training" : "evaluating (greedy, no learning)", static_cast<unsigned long long>(seed_),
           session_->table().stateCount(), session_->table().actionCount(), q_table_dir_.c_str(),
           protocol_params_.reset_service ? ("resets by " + reset_client_.getService()).c_str()
                                          : "no reset service: episodes start when the state is in ~start_region");
}

QLearningControllerNode::~QLearningControllerNode()
{
  {
    std::lock_guard<std::mutex> lock(reset_mutex_);
    stopping_ = true;
  }
  reset_wanted_.notify_all();
  if (reset_thread_.joinable())
    reset_thread_.join();
  // No state callback may run during the save (in a nodelet they run on another thread).
  joint_state_sub_.shutdown();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (learning_ && save_on_shutdown_ && !finished_training_)
  {
    std::string message;
    save("", message);
    // ROS may be shut down already: say it on the console too.
    std::printf("qlearning_controller: on shutdown: %s\n", message.c_str());
  }
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

  q_table_dir_ = defaultTableDirectory();
  priv.read("q_table_dir", q_table_dir_);
  if (q_table_dir_.empty())
    priv.fail("q_table_dir", "''", "must name a directory");
  priv.read("q_table_path", q_table_path_);
  try
  {
    resolve(q_table_path_);
  }
  catch (const QTableFileError& e)
  {
    priv.fail("q_table_path", "'" + q_table_path_ + "'", e.what());
  }
  priv.read("load_on_start", load_on_start_);
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

void QLearningControllerNode::command(double effort, const ros::Time& stamp)
{
  // A new message each time: in a nodelet manager the sim receives this very pointer.
  auto msg = boost::make_shared<sensor_msgs::JointState>();
  msg->header.stamp = stamp;
  msg->name = {"cart_joint"};
  msg->effort = {effort};
  command_pub_.publish(msg);
}

void QLearningControllerNode::onJointState(const sensor_msgs::JointStateConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  CartPoleState state;
  if (finished_training_ || !extractState(*msg, state))
    return;
  last_state_at_ = std::chrono::steady_clock::now();
  if (sim_silent_reported_)
  {
    sim_silent_reported_ = false;
    ROS_INFO("qlearning_controller: joint_states are back; going on");
  }

  const Reaction reaction = protocol_->onState(msg->header.stamp.toNSec(), state);
  report(reaction, msg->header.stamp);
  if (reaction.answer)
    command(reaction.effort, msg->header.stamp);
  if (reaction.episode_ended)
    endEpisode(msg->header.stamp, reaction.training_finished);
  if (reaction.request_reset && !finished_training_)
    requestReset();
}

void QLearningControllerNode::report(const Reaction& reaction, const ros::Time& stamp)
{
  const ControllerProtocol::Counts& c = protocol_->counts();
  if (reaction.kind == Reaction::Kind::Stale && dropped_state_warning_.ready())
    ROS_WARN(
        "qlearning_controller: dropped joint_states stamped %.6f, older than the last state (a replayed or "
        "reordered message; a restarted sim is recognised when it sends its state again). Dropped so far: %llu",
        stamp.toSec(), static_cast<unsigned long long>(c.stale));
  if (reaction.kind == Reaction::Kind::Stray && dropped_state_warning_.ready())
    ROS_WARN("qlearning_controller: dropped joint_states without a stamp among stamped ones. Dropped so far: %llu",
             static_cast<unsigned long long>(c.stray));
  if (reaction.first_unstamped)
    ROS_WARN(
        "qlearning_controller: joint_states carry no stamp (0): every message is taken as a new state, and "
        "commands go out unstamped");
  if (reaction.sim_restarted)
    ROS_WARN("qlearning_controller: joint_states time went back to %.3f s: the sim restarted; starting a new episode",
             stamp.toSec());
  if (reaction.waiting_for_start)
    ROS_INFO(
        "qlearning_controller: episode over; no reset service, so commanding 0 until the state is back inside "
        "~start_region (stand the pole up)");
}

void QLearningControllerNode::endEpisode(const ros::Time& stamp, bool training_finished)
{
  const EpisodeSummary& s = session_->lastEpisode();
  const double episode_wall = secondsSince(last_episode_end_);
  last_episode_end_ = std::chrono::steady_clock::now();

  // When training ends here, the table is saved before episode_stats says so: whoever acts on
  // the last message finds the final file.
  std::string saved;
  if (training_finished)
    save("", saved);

  EpisodeStats stats;
  stats.header.stamp = stamp;
  stats.episode = static_cast<std::uint32_t>(s.episode);
  stats.steps = s.steps;
  stats.episode_return = s.episode_return;
  stats.mean_return_100 = s.mean_return_window;
  stats.epsilon = s.epsilon;
  stats.alpha = s.alpha;
  stats.terminated = s.terminated;
  stats.truncated = s.truncated;
  stats.solved = s.solved;
  stats.total_steps = s.total_steps;
  stats.steps_per_second = episode_wall > 0.0 ? s.steps / episode_wall : 0.0;
  stats_pub_.publish(stats);

  const TrainingLimits& limits = config_.limits;
  if (limits.progress_every > 0 && s.episode % limits.progress_every == 0)
  {
    const double interval = secondsSince(last_progress_);
    const double rate = interval > 0.0 ? (s.total_steps - steps_at_last_progress_) / interval : 0.0;
    ROS_INFO("%s", progressLine(s, config_.task.solved_window, rate, secondsSince(started_)).c_str());
    steps_at_last_progress_ = s.total_steps;
    last_progress_ = std::chrono::steady_clock::now();
  }

  if (!learning_)
    return;
  if (training_finished)
  {
    finished_training_ = true;
    if (saved.rfind("nothing written", 0) == 0)
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
             static_cast<unsigned long long>(s.total_steps), secondsSince(started_), config_.task.solved_window,
             s.mean_return_window, saved.c_str());
    if (shutdown_when_finished_ && shutdown_)
      shutdown_();
    return;
  }
  if (checkpoint_every_ > 0 && s.episode % checkpoint_every_ == 0)
  {
    std::string message;
    if (save("", message))
      ROS_DEBUG("qlearning_controller: checkpoint: %s", message.c_str());
    else
      ROS_WARN("qlearning_controller: checkpoint failed: %s", message.c_str());
  }
}

bool QLearningControllerNode::save(const std::string& path, std::string& message)
{
  try
  {
    const std::string resolved = resolve(path);
    saveQTableFile(session_->table(), resolved);
    message = "saved " + std::to_string(session_->table().episodes) + " episodes, " +
              std::to_string(session_->table().steps) + " steps of training to " + resolved;
    return true;
  }
  catch (const QTableFileError& e)
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
    QTable table = loadQTableFile(path);
    const std::uint64_t episodes = table.episodes;
    const std::uint64_t steps = table.steps;
    const std::string mismatch = session_->replaceTable(std::move(table));
    if (!mismatch.empty())
      throw QTableFileError(path + " does not fit this controller: " + mismatch);
    response.success = true;
    response.message = "loaded " + path + " (" + std::to_string(episodes) + " episodes, " + std::to_string(steps) +
                       " steps of training)";
    ROS_INFO("qlearning_controller: load_q_table: %s", response.message.c_str());
  }
  catch (const QTableFileError& e)
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
  if (finished_training_ || sim_silent_reported_ || secondsSince(last_state_at_) < sim_timeout_)
    return;
  sim_silent_reported_ = true;
  ROS_WARN("qlearning_controller: no joint_states on %s for %.1f s: is cartpole_sim running? Waiting for it",
           joint_state_sub_.getTopic().c_str(), sim_timeout_);
}

void QLearningControllerNode::requestReset()
{
  {
    std::lock_guard<std::mutex> lock(reset_mutex_);
    reset_pending_ = true;
  }
  reset_wanted_.notify_one();
}

void QLearningControllerNode::resetLoop()
{
  bool failing = false;
  for (;;)
  {
    {
      std::unique_lock<std::mutex> lock(reset_mutex_);
      reset_wanted_.wait(lock, [this] { return reset_pending_ || stopping_; });
      if (stopping_)
        return;
      // Taken before the call: a request made while the call is under way (a short episode
      // can end before this thread sees the answer) is then served by the next call, not lost.
      reset_pending_ = false;
    }
    Reset reset;  // empty state: a random start
    if (reset_client_.call(reset) && reset.response.success)
    {
      if (failing)
        ROS_INFO("qlearning_controller: %s answers again; going on", reset_client_.getService().c_str());
      failing = false;
      continue;
    }
    if (!failing)
      ROS_WARN("qlearning_controller: reset call to %s failed%s; retrying until it answers",
               reset_client_.getService().c_str(),
               reset.response.message.empty() ? "" : (": " + reset.response.message).c_str());
    failing = true;
    if (!reset_client_.isValid())  // the persistent connection broke (sim restarted): reconnect
      reset_client_ = nh_.serviceClient<Reset>(reset_service_, true);
    std::unique_lock<std::mutex> lock(reset_mutex_);
    reset_pending_ = true;
    reset_wanted_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stopping_; });
    if (stopping_)
      return;
  }
}

}  // namespace cartpole_qlearning
