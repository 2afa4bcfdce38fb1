// cartpole_sim: the core's cart-pole as a ROS robot. Publishes joint_states and TF, takes
// cart_effort, serves ~reset, and in lockstep mode drives /clock.
#pragma once

#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/cartpole_simulation.h"
#include "cartpole_qlearning/random.h"
#include "cartpole_qlearning/wall_throttle.h"

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <tf2_ros/transform_broadcaster.h>

#include <chrono>
#include <memory>
#include <string>

namespace cartpole_qlearning
{
class CartPoleSimNode
{
public:
  // nh: the instance's namespace (topics, physics/* parameters); pnh: the node's private
  // namespace (sim parameters, ~reset). Throws ConfigError naming a bad parameter.
  CartPoleSimNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

private:
  enum class Mode
  {
    Realtime,  // steps on a wall timer, holding the last command
    Lockstep   // steps when the command answering the last state arrives
  };

  void readParameters();
  void onEffort(const std_msgs::Float64ConstPtr& msg);
  bool onReset(Reset::Request& request, Reset::Response& response);
  void onRealtimeTick(const ros::SteadyTimerEvent& event);
  void onLockstepTimeout(const ros::SteadyTimerEvent& event);

  // Steps with the force (after validation), advances the clock and publishes.
  void advance(double effort);
  // Publishes /clock (lockstep), joint_states and, at most at tf_rate in lockstep, TF. A repeat
  // (the same state and stamp again) sends no TF.
  void publishState(bool repeat = false);
  // A valid effort, clamped; false (with a throttled warning) for NaN or Inf.
  bool acceptEffort(double requested, double& effort) const;

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;

  // Parameters
  Mode mode_ = Mode::Realtime;
  CartPoleParams physics_;
  double start_state_bound_ = 0.05;
  std::uint64_t seed_ = 0;
  double command_timeout_ = 0.5;   // [s] realtime: an older command counts as zero
  double lockstep_timeout_ = 0.5;  // [s] lockstep: republish the state when unanswered this long
  double effort_limit_ = 10.0;     // [N]
  bool publish_tf_ = true;
  double tf_rate_ = 30.0;  // [Hz] lockstep: TF at most this often (wall clock)
  std::string world_frame_ = "world";
  std::string cart_frame_ = "cart";
  std::string pole_frame_ = "pole";
  double position_noise_std_ = 0.0;  // [m, rad] on published positions
  double velocity_noise_std_ = 0.0;  // [m/s, rad/s] on published velocities
  double effort_noise_std_ = 0.0;    // [N] on the applied force

  std::unique_ptr<CartPoleSimulation> simulation_;
  std::unique_ptr<RandomStream> noise_;
  ros::Time sim_time_;

  // Realtime: the last command and when it came.
  double held_effort_ = 0.0;
  std::chrono::steady_clock::time_point held_since_;
  bool have_command_ = false;

  // Lockstep: the last published state always awaits its answer, since this wall time.
  std::chrono::steady_clock::time_point published_at_;
  bool repeat_armed_ = false;  // a timer tick already found the state unanswered past the timeout
  std::chrono::steady_clock::time_point last_tf_;
  sensor_msgs::JointState joint_state_;  // the last state published (repeats send it again)
  mutable WallThrottle nonfinite_warning_{1.0};
  mutable WallThrottle clamp_warning_{1.0};

  ros::Publisher joint_state_pub_;
  ros::Publisher clock_pub_;
  ros::Subscriber effort_sub_;
  ros::ServiceServer reset_srv_;
  ros::SteadyTimer timer_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
};

}  // namespace cartpole_qlearning
