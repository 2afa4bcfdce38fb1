// cartpole_sim: the core's cart-pole as a ROS robot. Publishes joint_states and TF, takes
// joint_command (stamped), cart_effort and group_effort (unstamped), serves ~reset and
// ~reset_simulation, and in lockstep mode can drive /clock. It can pose as another cart-pole
// (SimSettings::pose: names, offsets, signs, another joint_states rate). What a command means in
// lockstep is the core's SimProtocol's decision; this class translates messages and services
// into its calls.
#pragma once

#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"
#include "cartpole_qlearning/node_settings/sim_settings.h"
#include "cartpole_qlearning/protocol/robot_interface.h"
#include "cartpole_qlearning/common/wall_throttle.h"

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/transform_broadcaster.h>

#include <memory>
#include <mutex>
#include <string>

namespace cartpole_qlearning
{
class CartPoleSimNode
{
public:
  // nh: the instance's namespace (topics, physics/* parameters); pnh: the node's private
  // namespace (sim parameters, ~reset). command_queue: where the command topics' callbacks
  // queue (nullptr: nh's queue); a nodelet passes the queue its lockstep thread serves.
  // Throws ConfigError naming a bad parameter.
  CartPoleSimNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, ros::CallbackQueue* command_queue = nullptr);

private:
  void readParameters();
  // One line on this instance's logger (name_).
  void say(ros::console::Level level, const char* format, ...) const __attribute__((format(printf, 3, 4)));
  void onJointCommand(const sensor_msgs::JointStateConstPtr& msg);
  void onEffort(const std_msgs::Float64ConstPtr& msg);
  // group_effort (std_msgs/Float64MultiArray, unstamped, as a JointGroupEffortController takes it): the slot
  // ~group_effort_index is the cart's.
  void onGroupEffort(const std_msgs::Float64MultiArrayConstPtr& msg);
  void onUnstampedEffort(double requested);
  bool onReset(Reset::Request& request, Reset::Response& response);
  // ~reset_simulation (std_srvs/Empty), posing as Gazebo: a random start; in lockstep, time set
  // back to the first tick.
  bool onResetSimulation(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  void onRealtimeTick(const ros::SteadyTimerEvent& event);
  void onLockstepTimer(const ros::SteadyTimerEvent& event);
  // Lockstep: a controller that subscribes gets the pending state at once (instead of after
  // lockstep_timeout); to everyone else nothing is sent.
  void onSubscriberConnect(const ros::SingleSubscriberPublisher& subscriber);

  // Lockstep: carries out the protocol's verdict on a command (step, or say why it was dropped).
  void apply(SimProtocol::Verdict verdict, double effort, const ros::Time& answers);
  // Lockstep: the pending state is answered with `effort`: the physics steps it drives, the next
  // state, and the samples after it that drive no step (~publish_period < tau), which nobody's
  // answer is waited for.
  void stepLockstep(double effort);
  // A physics step with the robot's effort (after validation): ~effort_sign turns it into the force.
  void step(double effort);
  // The state now as the posed robot's joint_states show it (unstamped).
  sensor_msgs::JointStatePtr stateMessage() const;
  // Publishes a new state message (/clock first when asked, then joint_states and, at most at
  // tf_rate in lockstep, TF): the state now, or the one before the last physics step.
  void publishState(const ros::Time& stamp, bool before_last_step = false);
  // Publishes the last state message again, unchanged (no TF: tf2 refuses a repeated stamp).
  void republishState();
  // A valid effort, clamped; false (with a throttled warning) for NaN or Inf.
  bool acceptEffort(double requested, double& effort) const;

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  std::string name_;  // the logger of this instance: ros.cartpole_qlearning.cartpole_sim.<its name>
  // Callbacks may run on two threads (a nodelet's command topics on the lockstep thread, its
  // timer and service on the manager's): each holds this while it runs.
  std::mutex mutex_;

  // Parameters
  SimSettings settings_;

  std::unique_ptr<CartPoleSimulation> simulation_;
  std::unique_ptr<SimProtocol> lockstep_;  // lockstep mode
  std::unique_ptr<CommandHold> hold_;      // realtime mode
  // Lockstep: which physics steps an answer drives (~publish_period against physics/tau).
  std::unique_ptr<SampledPhysics> sampled_;
  sensor_msgs::JointStatePtr before_last_step_;  // what a sample shows while the last step ends after it
  // The stamps of the samples published since the last step without waiting for their answers,
  // which are then dropped without a word.
  Stamp passed_from_ = 0;
  Stamp passed_to_ = 0;

  // The last state published. A new one is a new message: in a nodelet manager subscribers
  // receive this very pointer (no copy, no serialisation), so a published message never changes.
  sensor_msgs::JointStatePtr joint_state_;
  WallClock::time_point last_tf_;
  mutable WallThrottle nonfinite_warning_{1.0};
  mutable WallThrottle clamp_warning_{1.0};
  WallThrottle bad_command_warning_{1.0};
  WallThrottle dropped_warning_{1.0};

  ros::Publisher joint_state_pub_;
  ros::Publisher clock_pub_;
  ros::Subscriber command_sub_;
  ros::Subscriber effort_sub_;
  ros::Subscriber group_effort_sub_;
  ros::ServiceServer reset_srv_;
  ros::ServiceServer reset_simulation_srv_;
  ros::SteadyTimer timer_;
  ros::SteadyTimer publish_timer_;  // realtime, when ~publish_period is not physics/tau
  tf2_ros::TransformBroadcaster tf_broadcaster_;
};

}  // namespace cartpole_qlearning
