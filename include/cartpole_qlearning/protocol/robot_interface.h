// How the controller reads and drives a cart-pole that is not ours (Gazebo, a real robot, Isaac
// Sim): which joints it reads, how their readings map to the task's state (offset, sign, whole
// turns, velocities estimated when the driver sends none), what command it takes, and how often
// to decide when its joint_states come faster than physics/tau. No ROS: the node's conversions
// extract the raw readings from the message and write the command this says.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
enum class CommandType
{
  JointState,   // sensor_msgs/JointState, stamped with the state it answers (ours, Isaac Sim)
  Float64,      // std_msgs/Float64 (ros_control's JointEffortController)
  Float64Array  // std_msgs/Float64MultiArray (JointGroupEffortController): one slot is the cart's
};

struct RobotInterfaceParams
{
  std::string state_topic = "joint_states";     // ~state_topic: where the robot's joint_states come
  std::string command_topic = "joint_command";  // ~command_topic: where its commands go
  std::string cart_joint = "cart_joint";        // ~cart_joint: the cart's name in joint_states
  std::string pole_joint = "pole_joint";        // ~pole_joint
  double cart_zero = 0.0;                       // ~cart_zero [m]: the cart joint's reading at the track's centre
  double cart_sign = 1.0;                       // ~cart_sign: -1 when the joint's + points the other way
  double pole_upright = 0.0;                    // ~pole_upright [rad]: the pole joint's reading when upright
  double pole_angle_sign = 1.0;                 // ~pole_angle_sign: -1 when + leans the pole toward -x
  // ~velocity_smoothing in [0, 1): a velocity estimated from successive positions (a driver
  // that sends none) is v = s * v_before + (1 - s) * (difference / stamp gap); 0: the raw
  // difference. Ignored while the messages carry velocities.
  double velocity_smoothing = 0.0;
  CommandType command_type = CommandType::JointState;  // ~command_type
  std::string command_joint;                           // ~command_joint ("": cart_joint)
  std::size_t command_index = 0;                       // ~command_index: the cart's slot (float64_array)
  std::size_t command_size = 1;                        // ~command_size: the array's length (float64_array)
  double effort_sign = 1.0;                            // ~effort_sign: -1 when + effort pushes toward -x
  // ~max_effort [N]: the robot owner's limit; every command is clamped to it, whatever the table's
  // actions (a table's physics/force_mag is what it learnt with, not what the robot can take).
  // Infinity: none given.
  double max_effort = std::numeric_limits<double>::infinity();
  // ~decision_period [s]: decide at most once per this much time on the states' stamps (the
  // states between are answered with the effort held); 0: every message. Default: physics/tau.
  double decision_period = 0.02;
};

// An angle in (-pi, pi].
double wrapAngle(double angle);

// The task's effort within the robot's limit (max_effort), as the robot takes it (effort_sign).
inline double robotEffort(const RobotInterfaceParams& params, double effort)
{
  return params.effort_sign * std::clamp(effort, -params.max_effort, params.max_effort);
}

// One joint_states message as read from the robot (before any mapping).
struct JointReadings
{
  double cart_position = 0.0;
  double pole_position = 0.0;
  std::optional<double> cart_velocity;  // none: a position-only driver
  std::optional<double> pole_velocity;
};

// The task's state as such a robot reads it (the inverse of StateMapping, plus whole turns of the
// pole): what cartpole_sim publishes when it poses as another cart-pole. Without velocities when
// !velocities (a position-only driver).
JointReadings robotReadings(const RobotInterfaceParams& params, const CartPoleState& state, int pole_turns,
                            bool velocities);

// Readings -> the task's state: x = cart_sign * (cart - cart_zero), theta = the wrapped
// pole_angle_sign * (pole - pole_upright); velocities the message's (times the sign) or, when it
// has none, estimated from successive positions over the stamps' gap (the angle's difference
// wrapped, so a continuous joint crossing a whole turn gives no spike). The first position-only
// message, and one whose stamp does not move forward (a repeat, time set back), estimates 0 or
// keeps the estimate before it.
class StateMapping
{
public:
  explicit StateMapping(const RobotInterfaceParams& params);
  CartPoleState map(Stamp stamp, const JointReadings& readings);

private:
  RobotInterfaceParams params_;
  std::optional<Stamp> last_stamp_;
  double last_x_ = 0.0;
  double last_theta_ = 0.0;
  double x_dot_ = 0.0;
  double theta_dot_ = 0.0;
};

// Which states to decide on when they come faster than the decision period: decisions are due a
// period apart, and the first state at its due time (less a fifth of a period, for jitter) or
// after is decided. A repeat of the last decided stamp, a stamp 0 and a stamp older than the last decided one
// (time set back) are always passed on: the protocol judges those.
class DecisionClock
{
public:
  explicit DecisionClock(double period_s);
  struct Verdict
  {
    bool decide = true;
    bool slow = false;  // the decided states' gaps average over 1.5 periods (a moving mean)
  };
  Verdict onState(Stamp stamp);

private:
  Stamp period_;
  Stamp tolerance_;            // a state this much before its due time is decided
  std::optional<Stamp> last_;  // the last decided state's stamp
  Stamp due_ = 0;              // when the next decision is due
  double mean_gap_ = 0.0;      // [ns] between decided states (0: no gap yet)
};

// The sim posing as a robot whose joint_states come every `period` of sim time while its physics
// steps every tau (~publish_period: a 100 Hz or 30 Hz driver over physics/tau = 0.02 s). A sensor
// sampling the physics: the state stamped S shows the physics at its last step at or before S; the
// command answering the state at S drives the steps that start in [S, S + period), as the command in
// effect when they start. Times in ns of sim time; the physics starts at each start state (a reset).
class SampledPhysics
{
public:
  // tau, period > 0.
  SampledPhysics(Stamp tau, Stamp period);
  // A start state at `stamp`: the physics' next step starts there.
  void restart(Stamp stamp);
  // The steps to take after the state at `stamp` is answered, before the state at stamp + period.
  std::uint64_t stepsAfter(Stamp stamp);
  // Whether the answer to the state at `stamp` drives a step: else (a sample between two steps)
  // a lockstep sim need not wait for it.
  bool answerDrivesAStep(Stamp stamp) const
  {
    return next_step_ < stamp + period_;
  }
  // Whether the state at `stamp` is the physics before the last step taken: that step ends after
  // `stamp` (samples that come faster than the steps, or a period that is no multiple of tau).
  bool showsBeforeLastStep(Stamp stamp) const
  {
    return next_step_ > stamp;
  }

private:
  Stamp tau_;
  Stamp period_;
  Stamp next_step_ = 0;  // when the next step starts
};

}  // namespace cartpole_qlearning
