// qlearning_controller: a tabular Q-learning controller on the ROS graph, serving one robot or
// several (each in a namespace of its own) with one Q-table. For each robot it receives
// joint_states, decides with the core's ControllerProtocol (which drives the shared
// TrainingSession), answers on joint_command stamped with the state's stamp, ends episodes by
// calling that robot's reset service (or, for a robot without one, waits for it to be stood
// up), and publishes episode_stats. Which robot's state it decides on, and when (rounds over
// several robots unless ~sync is false, ~decision_period, the silence watchdog), is the core's
// RobotDispatch. It saves and loads its Q-table through services, and serves its learning
// settings (epsilon, alpha, gamma and their schedules) for live tuning with dynamic_reconfigure.
// What a run writes and decides (its folder, checkpoints, resume, the curve, which save replaces
// the default table, the evaluation verdict) is the core's RunApplication: the node carries it out
// and logs what it says on a logger of its own instance
// (ros.cartpole_qlearning.qlearning_controller.<its name, dots for slashes>).
#pragma once

#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/LearningConfig.h"
#include "cartpole_qlearning/LoadQTable.h"
#include "cartpole_qlearning/SaveQTable.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/node_settings/controller_settings.h"
#include "cartpole_qlearning/application/run_application.h"
#include "cartpole_qlearning/common/wall_throttle.h"
#include "cartpole_qlearning/learning/training_session.h"
#include "cartpole_qlearning/protocol/robot_dispatch.h"

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/spinner.h>
#include <sensor_msgs/JointState.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
class ControlReporter;

class QLearningControllerNode
{
public:
  // nh: the learner's namespace (topics of its own robot; physics, task, learning and training parameters); pnh:
  // the node's private namespace (controller parameters and services). When training ends (solved or max_episodes)
  // and ~shutdown_when_finished (default: shutdown_by_default), the controller ends the roslaunch that started it,
  // as Ctrl-C would (launch_control.h); when no roslaunch started it, it calls shutdown: the executable ends there;
  // a nodelet ends its manager only when asked. state_queue: where the joint_states callbacks queue (nullptr: nh's
  // queue); a nodelet passes the queue its lockstep thread serves. Throws ConfigError naming a bad parameter (a
  // ~load_on_start table or ~stats_csv that cannot be used included).
  QLearningControllerNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, std::function<void()> shutdown,
                          bool shutdown_by_default, ros::CallbackQueue* state_queue = nullptr);
  // What the constructor would refuse, without starting: reads the parameters as it does and opens
  // the table it would load (RunApplication::checkStart). Throws the same ConfigError; writes
  // nothing. For a launch's check before its nodes start (scripts/check_launch).
  static void checkParameters(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);
  // Saves the table when ~save_on_shutdown (training, RunApplication::shutdown), after giving up
  // any reset call under way.
  ~QLearningControllerNode();

  // Zero effort to every robot, and no state answered after it, before ROS shuts down (Ctrl-C, roslaunch's kill) or
  // a nodelet is unloaded: a robot may hold its last command.
  void stop();

  QLearningControllerNode(const QLearningControllerNode&) = delete;
  QLearningControllerNode& operator=(const QLearningControllerNode&) = delete;

private:
  // One robot the learner serves: its topics and its reset service (in the .cpp, with the
  // helpers it holds, which are the node's own and not installed).
  struct Robot;

  // Serves the learning settings in use on ~set_parameters (dynamic_reconfigure). Called with
  // mutex_ free: the server calls onReconfigure at once, which takes it.
  void startLiveTuning();
  // A change from a dynamic_reconfigure client: applied when the core accepts it, else refused
  // with the values in use put back into config (what the server then keeps and reports).
  void onReconfigure(LearningConfig& config, std::uint32_t level);
  // Starts the run (fresh, or going on with the run of a controller this process respawns) and
  // stores what a respawn of it needs to find it (~run/id, ~run/launcher, ~run/folder).
  void startRun();
  // Training or evaluation is over: ends the launch (or the node) when ~shutdown_when_finished, half a
  // second later (what was published last must leave first).
  void endWhenFinished();
  void setUpRobots(ros::CallbackQueue* state_queue);
  using StateEvent = ros::MessageEvent<sensor_msgs::JointState const>;
  using StateCallback = boost::function<void(const StateEvent&)>;
  void onJointState(std::size_t robot, const StateEvent& event);
  // Serves what the dispatch has to serve until it has nothing more or the run is over.
  void serveDue();
  bool onSave(SaveQTable::Request& request, SaveQTable::Response& response);
  bool onLoad(LoadQTable::Request& request, LoadQTable::Response& response);
  void onWatchdog(const ros::SteadyTimerEvent& event);
  // Says and publishes the robot's delay when it is found (or found other than before). Under mutex_.
  void reportFoundDelay();

  // Carries out what the robot's protocol decided about one of its states.
  void serve(const RobotDispatch::Turn& turn);
  // Carries out the application's episode end (statistics, progress, checkpoints, the final
  // save) and publishes episode_stats.
  void endEpisode(Robot& robot, const ros::Time& stamp, bool training_finished);
  std::string describe(const Robot& robot) const;

  // The node's log: every line on its logger (name_), "qlearning_controller: " before those said
  // with a prefix (the text users and the docs know the lines by).
  void say(const LogLines& log) const;

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  std::string name_;  // the logger of this instance (nodeLogger)
  // Callbacks may run on two threads (a nodelet's joint_states on the lockstep thread, its
  // services and timer on the manager's): each holds this while it runs.
  std::mutex mutex_;
  std::function<void()> shutdown_;

  // Parameters
  ControllerSettings settings_;
  std::vector<std::string> state_names_;  // as the trace names the rows (trace.h)

  std::unique_ptr<TrainingSession> session_;
  // The run around the session: what it writes and decides (finished(): serve no more states).
  std::unique_ptr<RunApplication> app_;
  std::vector<Robot> robots_;
  std::unique_ptr<RobotDispatch> dispatch_;

  WallThrottle bad_state_warning_{1.0};

  ros::Publisher stats_pub_;
  // ~found_delay_steps (std_msgs/UInt32, latched): the robot's delay as found from its states, each
  // time it is found anew (a greedy table not told ~predict_delay_steps); the log says it too.
  ros::Publisher delay_pub_;
  std::optional<unsigned> delay_said_;
  // ~mode control: how each robot is held, said and published on control_stats (none otherwise).
  std::unique_ptr<ControlReporter> control_;
  // ~save_q_table and ~load_q_table run on a thread of their own: writing or reading a large
  // table takes seconds, and states must be answered meanwhile (a node's states and timer share
  // one thread). Only the copy of the table to save and the swap of a table read hold mutex_.
  ros::CallbackQueue services_queue_;
  std::unique_ptr<ros::AsyncSpinner> services_spinner_;
  ros::ServiceServer save_srv_;
  ros::ServiceServer load_srv_;
  ros::NodeHandle timers_nh_;  // nh_ on the states' queue: the watchdog's and end_timer_'s
  ros::SteadyTimer watchdog_;
  // Ends the launch (or the node) a moment after training finished (endWhenFinished).
  ros::SteadyTimer end_timer_;
  static constexpr double kLingerSeconds = 0.5;
  // Given to the server so that its updates and its callback never run at the same time.
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<LearningConfig>> reconfigure_;
  bool reconfigure_started_ = false;  // the server's first callback (at its start) has run
};

}  // namespace cartpole_qlearning
