#include "cartpole_qlearning/ros/conversions.h"

#include <ros/node_handle.h>

#include "cartpole_qlearning/learning/schedule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <variant>

namespace cartpole_qlearning
{
namespace
{
// Index of a joint by name, or -1.
int jointIndex(const sensor_msgs::JointState& msg, const std::string& name)
{
  const auto it = std::find(msg.name.begin(), msg.name.end(), name);
  return it == msg.name.end() ? -1 : static_cast<int>(it - msg.name.begin());
}
}  // namespace

Reading<JointReadings> readingsFromJointState(const sensor_msgs::JointState& msg, const std::string& cart_joint,
                                              const std::string& pole_joint)
{
  const int cart = jointIndex(msg, cart_joint);
  const int pole = jointIndex(msg, pole_joint);
  if (cart < 0 || pole < 0)
    return {std::nullopt, "dropped joint_states without " + (cart < 0 ? cart_joint : pole_joint)};
  const bool velocities = !msg.velocity.empty();
  if (msg.position.size() != msg.name.size() || (velocities && msg.velocity.size() != msg.name.size()))
    return {std::nullopt, "dropped joint_states with " + std::to_string(msg.name.size()) + " names but " +
                              std::to_string(msg.position.size()) + " positions and " +
                              std::to_string(msg.velocity.size()) + " velocities"};
  JointReadings readings{msg.position[cart], msg.position[pole], std::nullopt, std::nullopt};
  if (velocities)
  {
    readings.cart_velocity = msg.velocity[cart];
    readings.pole_velocity = msg.velocity[pole];
  }
  if (!std::isfinite(readings.cart_position) || !std::isfinite(readings.pole_position) ||
      !std::isfinite(readings.cart_velocity.value_or(0.0)) || !std::isfinite(readings.pole_velocity.value_or(0.0)))
    return {std::nullopt, "dropped joint_states with a non-finite position or velocity"};
  return {readings, ""};
}

sensor_msgs::JointState jointStateFromState(const CartPoleState& state, double applied_effort, const ros::Time& stamp,
                                            const std::string& cart_joint, const std::string& pole_joint)
{
  sensor_msgs::JointState msg;
  msg.header.stamp = stamp;
  msg.name = {cart_joint, pole_joint};
  msg.position = {state[0], state[2]};
  msg.velocity = {state[1], state[3]};
  msg.effort = {applied_effort, 0.0};
  return msg;
}

sensor_msgs::JointState jointStateFromReadings(const JointReadings& r, double applied_effort, const ros::Time& stamp,
                                               const std::string& cart_joint, const std::string& pole_joint)
{
  sensor_msgs::JointState msg;
  msg.header.stamp = stamp;
  msg.name = {cart_joint, pole_joint};
  msg.position = {r.cart_position, r.pole_position};
  if (r.cart_velocity && r.pole_velocity)
    msg.velocity = {*r.cart_velocity, *r.pole_velocity};
  msg.effort = {applied_effort, 0.0};
  return msg;
}

sensor_msgs::JointState commandMessage(double effort, const ros::Time& stamp, const std::string& cart_joint)
{
  sensor_msgs::JointState msg;
  msg.header.stamp = stamp;
  msg.name = {cart_joint};
  msg.effort = {effort};
  return msg;
}

std_msgs::Float64 float64Command(double effort)
{
  std_msgs::Float64 msg;
  msg.data = effort;
  return msg;
}

std_msgs::Float64MultiArray float64ArrayCommand(double effort, std::size_t index, std::size_t size)
{
  std_msgs::Float64MultiArray msg;
  msg.data.assign(size, 0.0);
  msg.data.at(index) = effort;
  return msg;
}

Reading<double> effortFromCommand(const sensor_msgs::JointState& msg, const std::string& cart_joint)
{
  const int index = jointIndex(msg, cart_joint);
  if (index < 0 || msg.effort.size() != msg.name.size())
    return {std::nullopt, "dropped a joint_command without an effort for " + cart_joint +
                              " (names: " + std::to_string(msg.name.size()) +
                              ", efforts: " + std::to_string(msg.effort.size()) + ")"};
  return {msg.effort[index], ""};
}

std::vector<geometry_msgs::TransformStamped> transformsFromState(const CartPoleState& state, double track_y,
                                                                 const ros::Time& stamp, const std::string& world_frame,
                                                                 const std::string& cart_frame,
                                                                 const std::string& pole_frame)
{
  geometry_msgs::TransformStamped cart;
  cart.header.stamp = stamp;
  cart.header.frame_id = world_frame;
  cart.child_frame_id = cart_frame;
  cart.transform.translation.x = state[0];
  cart.transform.translation.y = track_y;
  cart.transform.rotation.w = 1.0;
  geometry_msgs::TransformStamped pole;
  pole.header.stamp = stamp;
  pole.header.frame_id = cart_frame;
  pole.child_frame_id = pole_frame;
  // theta about +y: positive theta tips the pole's top toward +x.
  pole.transform.rotation.y = std::sin(state[2] / 2.0);
  pole.transform.rotation.w = std::cos(state[2] / 2.0);
  return {cart, pole};
}

ControlStats controlStats(const ControlStatsValues& values, const std::string& robot, const ros::Time& stamp)
{
  ControlStats msg;
  msg.header.stamp = stamp;
  msg.robot = robot;
  msg.seconds = values.seconds;
  msg.balanced_seconds = values.balanced_seconds;
  msg.longest_seconds = values.longest_seconds;
  msg.current_seconds = values.current_seconds;
  msg.falls = values.falls;
  msg.decisions = values.decisions;
  msg.clamped = values.clamped;
  msg.upright_seconds = values.upright_seconds;
  msg.swing_ups = values.swing_ups;
  msg.last_swing_up_seconds = values.last_swing_up_seconds;
  msg.longest_swing_up_seconds = values.longest_swing_up_seconds;
  msg.rail_hits = values.rail_hits;
  return msg;
}

EpisodeStats learnerEpisodeStats(const EpisodeSummary& s, const std::string& robot, const ros::Time& stamp,
                                 double steps_per_second)
{
  EpisodeStats stats;
  stats.header.stamp = stamp;
  stats.robot = robot;
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
  stats.steps_per_second = steps_per_second;
  return stats;
}

EpisodeStats robotEpisodeStats(const EpisodeSummary& s, const std::string& robot, const ros::Time& stamp,
                               double steps_per_second)
{
  EpisodeStats stats = learnerEpisodeStats(s, robot, stamp, steps_per_second);
  stats.episode = static_cast<std::uint32_t>(s.robot_episode);
  stats.mean_return_100 = s.robot_mean_return_window;
  stats.total_steps = s.robot_total_steps;
  return stats;
}

namespace
{
// The server's fields and their keys, in cfg/Learning.cfg's order (ros_conversions_test holds the
// two alike).
using Field = std::variant<double LearningConfig::*, std::string LearningConfig::*>;
const std::pair<const char*, Field> kFields[] = {{"epsilon_override", &LearningConfig::epsilon_override},
                                                 {"alpha_override", &LearningConfig::alpha_override},
                                                 {"gamma", &LearningConfig::gamma},
                                                 {"epsilon_schedule", &LearningConfig::epsilon_schedule},
                                                 {"epsilon_start", &LearningConfig::epsilon_start},
                                                 {"epsilon_min", &LearningConfig::epsilon_min},
                                                 {"epsilon_decay_episodes", &LearningConfig::epsilon_decay_episodes},
                                                 {"epsilon_decay_rate", &LearningConfig::epsilon_decay_rate},
                                                 {"epsilon_log_divisor", &LearningConfig::epsilon_log_divisor},
                                                 {"alpha_schedule", &LearningConfig::alpha_schedule},
                                                 {"alpha_start", &LearningConfig::alpha_start},
                                                 {"alpha_min", &LearningConfig::alpha_min},
                                                 {"alpha_decay_episodes", &LearningConfig::alpha_decay_episodes},
                                                 {"alpha_decay_rate", &LearningConfig::alpha_decay_rate},
                                                 {"alpha_log_divisor", &LearningConfig::alpha_log_divisor}};

template <typename T>
void readField(const ParameterSource& source, const char* key, T& field)
{
  T value = field;
  try
  {
    if (source.get(key, value))
      field = value;
  }
  catch (const ConfigError&)
  {
  }
}
}  // namespace

std::vector<std::string> learningConfigKeys()
{
  std::vector<std::string> keys;
  for (const auto& field : kFields)
    keys.push_back(field.first);
  return keys;
}

void setLearningConfigParams(const LearningConfig& config, const ros::NodeHandle& nh)
{
  for (const auto& [key, field] : kFields)
    std::visit([&, key = key](auto member) { nh.setParam(key, config.*member); }, field);
}

LearningSettings learningSettingsLeft(const ParameterSource& source, const LearningSettings& in_use)
{
  LearningConfig config = toConfig(in_use);
  for (const auto& [key, field] : kFields)
    std::visit([&, key = key](auto member) { readField(source, key, config.*member); }, field);
  LearningSettings left = in_use;
  fromConfig(config, left);  // an unknown schedule name leaves that schedule as it is
  return left;
}

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

std::string asServerField(std::string message)
{
  const std::size_t slash = message.find('/');
  if (slash < message.find(" = "))
    message[slash] = '_';
  return message;
}

}  // namespace cartpole_qlearning
