// qlearning_controller: a tabular Q-learning controller on the ROS graph. Receives
// joint_states, decides with the core's ControllerProtocol (which drives the TrainingSession),
// answers each state on joint_command stamped with the state's stamp, ends episodes by calling
// the sim's reset (or, for a robot without one, waits for it to be stood up), publishes
// episode_stats, and saves or loads its Q-table.
#pragma once

#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/LoadQTable.h"
#include "cartpole_qlearning/SaveQTable.h"
#include "cartpole_qlearning/config.h"
#include "cartpole_qlearning/lockstep_protocol.h"
#include "cartpole_qlearning/training_session.h"
#include "cartpole_qlearning/wall_throttle.h"

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace cartpole_qlearning
{
class QLearningControllerNode
{
public:
  // nh: the instance's namespace (topics; physics, task, learning and training parameters);
  // pnh: the node's private namespace (controller parameters and services). shutdown is called
  // when training ends (solved or max_episodes) if ~shutdown_when_finished, whose default is
  // shutdown_by_default: the executable ends there; a nodelet ends its manager only when asked.
  // Throws ConfigError naming a bad parameter, QTableFileError for a bad ~load_on_start file.
  // state_queue: where the joint_states callbacks queue (nullptr: nh's queue); a nodelet passes
  // the queue its lockstep thread serves.
  QLearningControllerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, std::function<void()> shutdown,
                          bool shutdown_by_default, ros::CallbackQueue* state_queue = nullptr);
  // Saves the table when ~save_on_shutdown (training), and stops the reset thread.
  ~QLearningControllerNode();

  QLearningControllerNode(const QLearningControllerNode&) = delete;
  QLearningControllerNode& operator=(const QLearningControllerNode&) = delete;

private:
  void readParameters();
  void onJointState(const sensor_msgs::JointStateConstPtr& msg);
  bool onSave(SaveQTable::Request& request, SaveQTable::Response& response);
  bool onLoad(LoadQTable::Request& request, LoadQTable::Response& response);
  void onWatchdog(const ros::SteadyTimerEvent& event);

  // The state in a message, or false (with a throttled warning) when it cannot be used.
  bool extractState(const sensor_msgs::JointState& msg, CartPoleState& state) const;
  void command(double effort, const ros::Time& stamp);
  // Statistics, progress, checkpoints and, when training reached its limits, the final save.
  void endEpisode(const ros::Time& stamp, bool training_finished);
  // Logs what the protocol did with a state that was not simply answered.
  void report(const Reaction& reaction, const ros::Time& stamp);
  // Saves to a user path (empty: the default); returns the message for the log or service.
  bool save(const std::string& path, std::string& message);
  std::string resolve(const std::string& path) const;

  // The reset call runs on a thread of its own: a blocking service call from this node's
  // callback would never return if the sim's service ran on the same single thread (nodelets).
  void requestReset();
  void resetLoop();

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  // Callbacks may run on two threads (a nodelet's joint_states on the lockstep thread, its
  // services and timer on the manager's): each holds this while it runs.
  std::mutex mutex_;
  std::function<void()> shutdown_;
  bool shutdown_when_finished_;

  // Parameters
  TrainingConfig config_;
  bool learning_ = true;  // ~mode: train (true) or evaluate
  std::uint64_t seed_ = 0;
  std::string q_table_dir_;
  std::string q_table_path_ = "q_table.yaml";
  std::string load_on_start_;
  std::uint64_t checkpoint_every_ = 100;
  bool save_on_shutdown_ = true;
  double sim_timeout_ = 2.0;                          // [s] wall
  std::string reset_service_ = "cartpole_sim/reset";  // "": a robot that cannot be reset on command
  ControllerProtocolParams protocol_params_;

  std::unique_ptr<TrainingSession> session_;
  std::unique_ptr<ControllerProtocol> protocol_;
  bool finished_training_ = false;

  // Wall-clock bookkeeping for steps/s and the sim watchdog.
  std::chrono::steady_clock::time_point started_;
  std::chrono::steady_clock::time_point last_episode_end_;
  std::chrono::steady_clock::time_point last_state_at_;
  std::uint64_t steps_at_last_progress_ = 0;
  std::chrono::steady_clock::time_point last_progress_;
  bool sim_silent_reported_ = false;
  mutable WallThrottle bad_state_warning_{1.0};
  WallThrottle dropped_state_warning_{1.0};

  ros::Subscriber joint_state_sub_;
  ros::Publisher command_pub_;
  ros::Publisher stats_pub_;
  ros::ServiceServer save_srv_;
  ros::ServiceServer load_srv_;
  ros::ServiceClient reset_client_;  // used by the reset thread only
  ros::SteadyTimer watchdog_;

  std::mutex reset_mutex_;
  std::condition_variable reset_wanted_;
  bool reset_pending_ = false;
  bool stopping_ = false;
  std::thread reset_thread_;
};

}  // namespace cartpole_qlearning
