// The ROS layer's message conversions: joint states, joint commands, TF, episode_stats and the
// live-tuning server's fields, to and from the core's types. Free functions with no node, no
// master and no logging: a refused message comes back with the text the node logs.
#pragma once

#include "cartpole_qlearning/ControlStats.h"
#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/application/control_meter.h"
#include "cartpole_qlearning/LearningConfig.h"
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/learning_settings.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/protocol/robot_interface.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>

#include <optional>
#include <string>
#include <vector>

namespace ros
{
class NodeHandle;
}

namespace cartpole_qlearning
{
// What a message said, or why it was refused ("dropped joint_states without pole_joint").
template <typename T>
struct Reading
{
  std::optional<T> value;
  std::string refusal;  // empty when there is a value

  explicit operator bool() const
  {
    return value.has_value();
  }
};

// joint_states from any cart-pole -> the two joints' readings, found by name in any order among
// others. Positions one per name; velocities one per name or none at all (a position-only
// driver: the core's StateMapping estimates them); finite.
Reading<JointReadings> readingsFromJointState(const sensor_msgs::JointState& msg, const std::string& cart_joint,
                                              const std::string& pole_joint);
// The state -> joint_states as the sim publishes it: both joints' positions, velocities and
// efforts (the cart's the force applied in the last step, the pole's 0: it is not actuated).
sensor_msgs::JointState jointStateFromState(const CartPoleState& state, double applied_effort, const ros::Time& stamp,
                                            const std::string& cart_joint = "cart_joint",
                                            const std::string& pole_joint = "pole_joint");

// A robot's readings -> joint_states (the sim posing as another cart-pole, robotReadings): both
// joints' positions, velocities when the readings have them, efforts as jointStateFromState's.
sensor_msgs::JointState jointStateFromReadings(const JointReadings& readings, double applied_effort,
                                               const ros::Time& stamp, const std::string& cart_joint,
                                               const std::string& pole_joint);

// The controller's joint_command: the cart's effort [N], stamped with the state it answers.
sensor_msgs::JointState commandMessage(double effort, const ros::Time& stamp,
                                       const std::string& cart_joint = "cart_joint");
// The effort as ros_control's JointEffortController takes it.
std_msgs::Float64 float64Command(double effort);
// The effort in slot `index` of `size` (JointGroupEffortController), the other slots 0.
std_msgs::Float64MultiArray float64ArrayCommand(double effort, std::size_t index, std::size_t size);
// joint_command -> the effort of the cart joint (as sent: the sim checks and clamps it).
Reading<double> effortFromCommand(const sensor_msgs::JointState& msg, const std::string& cart_joint = "cart_joint");

// TF world -> cart (x along the track, which lies at y = track_y) -> pole (theta about +y).
std::vector<geometry_msgs::TransformStamped> transformsFromState(const CartPoleState& state, double track_y,
                                                                 const ros::Time& stamp, const std::string& world_frame,
                                                                 const std::string& cart_frame,
                                                                 const std::string& pole_frame);

// episode_stats at an episode's end. On the learner's topic: episode, mean return and total
// steps over all robots; on a robot's own topic: that robot's. steps_per_second is the caller's.
// ~mode control's report (ControlMeter) as a message.
ControlStats controlStats(const ControlStatsValues& values, const std::string& robot, const ros::Time& stamp);
EpisodeStats learnerEpisodeStats(const EpisodeSummary& summary, const std::string& robot, const ros::Time& stamp,
                                 double steps_per_second);
EpisodeStats robotEpisodeStats(const EpisodeSummary& summary, const std::string& robot, const ros::Time& stamp,
                               double steps_per_second);

// A service's response (success, message) from the core's answer (RunApplication's ServiceAnswer);
// returns what the answer has to say, for the node's log.
template <typename Answer, typename Response>
const auto& toResponse(const Answer& answer, Response& response)
{
  response.success = answer.success;
  response.message = answer.message;
  return answer.log;
}

// Live tuning: the server's fields <-> the core's settings. An override is off when negative
// (the server shows it as -1).
LearningConfig toConfig(const LearningSettings& settings);
// Empty when every field could be read (the values themselves are the core's to check); a
// schedule name the core does not know leaves that schedule's type as it was and is refused
// with the server's field name ("alpha_schedule = 'cosine' is not allowed (...)").
std::string fromConfig(const LearningConfig& config, LearningSettings& settings);
// The core names a schedule's field as the config file does ("epsilon/min = ..."); the server's
// field is "epsilon_min".
std::string asServerField(std::string message);
// The server's fields as it keeps them on the parameter server, under the node's private
// namespace ("gamma", "epsilon_schedule", ...): keys the node's parameter check must let pass.
std::vector<std::string> learningConfigKeys();
// Puts the live-tuning fields under nh (the controller's private namespace), where the
// dynamic_reconfigure server reads its first values: it then starts from them, with no moment in
// which it serves others.
void setLearningConfigParams(const LearningConfig& config, const ros::NodeHandle& nh);
// What an earlier server left in source (the node's private namespace): the settings in use with
// the fields present there replaced. A value of the wrong type leaves its field as it was, as the
// server's own start does.
LearningSettings learningSettingsLeft(const ParameterSource& source, const LearningSettings& in_use);

}  // namespace cartpole_qlearning
