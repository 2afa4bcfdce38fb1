#include "cartpole_qlearning/qlearning_controller_node.h"

#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/q_table_file.h"
#include "cartpole_qlearning/ros_parameter_source.h"

#include <std_msgs/Float64.h>

#include <algorithm>
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
                                                 std::function<void()> finished)
  : nh_(nh), pnh_(pnh), finished_(std::move(finished))
{
  readParameters();
  session_ = std::make_unique<TrainingSession>(config_.task, config_.agent, seed_, learning_);
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
  // An answer that went out while the sim was not yet subscribed is sent again when the sim
  // repeats the state (see onJointState).
  effort_pub_ = nh_.advertise<std_msgs::Float64>("cart_effort", 10);
  stats_pub_ = nh_.advertise<EpisodeStats>("episode_stats", 100);
  save_srv_ = pnh_.advertiseService("save_q_table", &QLearningControllerNode::onSave, this);
  load_srv_ = pnh_.advertiseService("load_q_table", &QLearningControllerNode::onLoad, this);
  // Persistent: a new connection per episode would cost a master lookup and a TCP set-up.
  reset_client_ = nh_.serviceClient<Reset>(reset_service_, true);
  reset_thread_ = std::thread(&QLearningControllerNode::resetLoop, this);
  watchdog_ = nh_.createSteadyTimer(ros::WallDuration(std::min(0.5, sim_timeout_ / 2.0)),
                                    &QLearningControllerNode::onWatchdog, this);
  // TCP_NODELAY: in lockstep every step is a message each way; Nagle's delay would dominate.
  joint_state_sub_ = nh_.subscribe("joint_states", 10, &QLearningControllerNode::onJointState, this,
                                   ros::TransportHints().tcpNoDelay());
  ROS_INFO("qlearning_controller: %s, seed %llu, %zu states x %zu actions, tables under %s",
           learning_ ? "training" : "evaluating (greedy, no learning)", static_cast<unsigned long long>(seed_),
           session_->table().stateCount(), session_->table().actionCount(), q_table_dir_.c_str());
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

  const RosParameterSource priv(pnh_);
  // The launch files' stop_when_solved and max_episodes arrive as private parameters; they
  // override the shared training/ keys for this controller only.
  config_.limits.stop_when_solved = valueOr(priv, "stop_when_solved", config_.limits.stop_when_solved);
  const std::int64_t max_episodes =
      valueOr<std::int64_t>(priv, "max_episodes", static_cast<std::int64_t>(config_.limits.max_episodes));
  if (max_episodes < 1)
    refuseParameter(pnh_, "max_episodes", std::to_string(max_episodes), "must be a whole number >= 1");
  config_.limits.max_episodes = static_cast<std::uint64_t>(max_episodes);

  const std::string mode = valueOr<std::string>(priv, "mode", "train");
  if (mode != "train" && mode != "evaluate")
    refuseParameter(pnh_, "mode", "'" + mode + "'", "allowed: train, evaluate");
  learning_ = mode == "train";

  const std::int64_t seed = valueOr<std::int64_t>(priv, "seed", 0);
  if (seed < 0)
    refuseParameter(pnh_, "seed", std::to_string(seed), "must be a whole number >= 0");
  seed_ = static_cast<std::uint64_t>(seed);

  q_table_dir_ = valueOr(priv, "q_table_dir", defaultTableDirectory());
  if (q_table_dir_.empty())
    refuseParameter(pnh_, "q_table_dir", "''", "must name a directory");
  q_table_path_ = valueOr(priv, "q_table_path", q_table_path_);
  try
  {
    resolve(q_table_path_);
  }
  catch (const QTableFileError& e)
  {
    refuseParameter(pnh_, "q_table_path", "'" + q_table_path_ + "'", e.what());
  }
  load_on_start_ = valueOr(priv, "load_on_start", load_on_start_);

  const std::int64_t checkpoint = valueOr<std::int64_t>(priv, "checkpoint_every", 100);
  if (checkpoint < 0)
    refuseParameter(pnh_, "checkpoint_every", std::to_string(checkpoint), "must be a whole number >= 0 (0: never)");
  checkpoint_every_ = static_cast<std::uint64_t>(checkpoint);
  save_on_shutdown_ = valueOr(priv, "save_on_shutdown", save_on_shutdown_);
  sim_timeout_ = valueOr(priv, "sim_timeout", sim_timeout_);
  if (!(std::isfinite(sim_timeout_) && sim_timeout_ > 0.0))
    refuseParameter(pnh_, "sim_timeout", std::to_string(sim_timeout_), "must be finite and > 0");
  reset_service_ = valueOr(priv, "reset_service", reset_service_);
  if (reset_service_.empty())
    refuseParameter(pnh_, "reset_service", "''", "must name the sim's reset service");
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

void QLearningControllerNode::command(double effort)
{
  last_effort_ = effort;
  answer_unheard_ = effort_pub_.getNumSubscribers() == 0;
  std_msgs::Float64 msg;
  msg.data = effort;
  effort_pub_.publish(msg);
}

void QLearningControllerNode::onJointState(const sensor_msgs::JointStateConstPtr& msg)
{
  CartPoleState state;
  if (finished_training_ || !extractState(*msg, state))
    return;
  last_state_at_ = std::chrono::steady_clock::now();
  if (sim_silent_reported_)
  {
    sim_silent_reported_ = false;
    ROS_INFO("qlearning_controller: joint_states are back; going on");
  }

  const ros::Time stamp = msg->header.stamp;
  if (have_stamp_ && stamp == last_stamp_)
  {
    // The sim sent this state again (lockstep, no answer within its timeout). Answer again, the
    // same effort and without learning twice, only if the first answer went out with nobody
    // subscribed to cart_effort. Otherwise it is on its way (a slow answer, a stalled sim): a
    // second one would be taken by the sim for its next state, and every action after it would
    // land one state late. After the episode's end there is nothing to answer.
    if (!awaiting_reset_ && answer_unheard_)
      command(last_effort_);
    return;
  }
  if (have_stamp_ && stamp < last_stamp_)
  {
    // Time went back: the sim was restarted. The running episode cannot be finished.
    ROS_WARN(
        "qlearning_controller: joint_states time went back (%.3f -> %.3f s): the sim restarted; "
        "starting a new episode",
        last_stamp_.toSec(), stamp.toSec());
    session_->abortEpisode();
    awaiting_reset_ = false;
  }
  if (awaiting_reset_)
  {
    // In realtime the sim goes on stepping until it handles the reset; those states come after
    // a fall and so are terminal themselves. (After a truncation one such state can still start
    // the episode; in lockstep none comes, the sim waits for the reset.) The stamps cannot
    // decide: the sim's are on its own clock, which need not be this node's.
    if (session_->task().isTerminal(state))
      return;
    awaiting_reset_ = false;
  }
  last_stamp_ = stamp;
  have_stamp_ = true;

  if (!session_->inEpisode())
  {
    // Joining a sim that waits on a fallen pole (another controller's episode ended there):
    // nothing to learn from it, ask for a fresh start.
    if (session_->task().isTerminal(state))
    {
      requestReset();
      return;
    }
    command(session_->beginEpisode(state));
    return;
  }
  const Decision decision = session_->observe(state);
  if (!decision.episode_over)
  {
    command(decision.effort);
    return;
  }
  endEpisode(stamp);
}

void QLearningControllerNode::endEpisode(const ros::Time& stamp)
{
  const EpisodeSummary& s = session_->lastEpisode();
  const double episode_wall = secondsSince(last_episode_end_);
  last_episode_end_ = std::chrono::steady_clock::now();

  // When training ends here, the table is saved before episode_stats says so: whoever acts on
  // the last message finds the final file.
  const TrainingLimits& limits = config_.limits;
  const bool finish = learning_ && limits.reached(s.episode, s.solved);
  std::string saved;
  if (finish)
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

  if (limits.progress_every > 0 && s.episode % limits.progress_every == 0)
  {
    const double interval = secondsSince(last_progress_);
    const double rate = interval > 0.0 ? (s.total_steps - steps_at_last_progress_) / interval : 0.0;
    ROS_INFO("%s", progressLine(s, config_.task.solved_window, rate, secondsSince(started_)).c_str());
    steps_at_last_progress_ = s.total_steps;
    last_progress_ = std::chrono::steady_clock::now();
  }

  if (learning_)
  {
    if (finish && saved.rfind("nothing written", 0) == 0)
    {
      // Keep the trained table alive: the user can still save it elsewhere with ~save_q_table.
      ROS_ERROR(
          "qlearning_controller: training ended (%s, episode %llu) but the table could not be saved: %s. "
          "The node keeps running: call ~save_q_table with another path",
          s.solved ? "solved" : "max_episodes", static_cast<unsigned long long>(s.episode), saved.c_str());
      finished_training_ = true;
      return;
    }
    if (finish)
    {
      ROS_INFO(
          "qlearning_controller: %s after %llu episodes, %llu steps, %.1f s (mean return of the last %u: %.2f); %s",
          s.solved ? "SOLVED" : "NOT solved, max_episodes reached", static_cast<unsigned long long>(s.episode),
          static_cast<unsigned long long>(s.total_steps), secondsSince(started_), config_.task.solved_window,
          s.mean_return_window, saved.c_str());
      finished_training_ = true;
      if (finished_)
        finished_();
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
  requestReset();
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
  response.success = save(request.path, response.message);
  if (response.success)
    ROS_INFO("qlearning_controller: save_q_table: %s", response.message.c_str());
  else
    ROS_WARN("qlearning_controller: save_q_table: %s", response.message.c_str());
  return true;
}

bool QLearningControllerNode::onLoad(LoadQTable::Request& request, LoadQTable::Response& response)
{
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
  if (finished_training_ || sim_silent_reported_ || secondsSince(last_state_at_) < sim_timeout_)
    return;
  sim_silent_reported_ = true;
  ROS_WARN("qlearning_controller: no joint_states on %s for %.1f s: is cartpole_sim running? Waiting for it",
           joint_state_sub_.getTopic().c_str(), sim_timeout_);
}

void QLearningControllerNode::requestReset()
{
  awaiting_reset_ = true;
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
