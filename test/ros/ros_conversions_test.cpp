// The ROS layer's message conversions (ros/conversions.h), built and read without a master: what
// the sim publishes is what the controller reads, commands carry the stamp of the state they
// answer, a refused message says why in the words the nodes log, episode_stats on the learner's
// and a robot's topic, and the live-tuning server's fields to and from the core's settings.
#include "cartpole_qlearning/SaveQTable.h"
#include "cartpole_qlearning/ros/conversions.h"
#include "../../src/ros/start_up.h"

#include "cartpole_qlearning/learning/schedule.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>

using namespace cartpole_qlearning;

namespace
{
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

ros::Time stampAt(std::uint64_t nsec)
{
  ros::Time time;
  time.fromNSec(nsec);
  return time;
}

sensor_msgs::JointState joints(std::vector<std::string> names, std::vector<double> positions,
                               std::vector<double> velocities)
{
  sensor_msgs::JointState msg;
  msg.name = std::move(names);
  msg.position = std::move(positions);
  msg.velocity = std::move(velocities);
  return msg;
}

// Every field the server and the core share, none of them at its default.
LearningSettings unusualSettings()
{
  LearningSettings s;
  s.gamma = 0.91;
  s.epsilon_override = 0.0;  // greedy: a valid override, not "none"
  s.alpha_override = 0.25;
  s.epsilon = {ScheduleType::Exponential, 0.8, 0.04, 321.0, 0.97, 12.0};
  s.alpha = {ScheduleType::Linear, 0.6, 0.07, 77.0, 0.93, 18.0};
  return s;
}

void expectSameSettings(const LearningSettings& expected, const LearningSettings& actual)
{
  EXPECT_EQ(expected.gamma, actual.gamma);
  EXPECT_EQ(expected.epsilon_override, actual.epsilon_override);
  EXPECT_EQ(expected.alpha_override, actual.alpha_override);
  for (const auto& [e, a] : {std::pair(expected.epsilon, actual.epsilon), std::pair(expected.alpha, actual.alpha)})
  {
    EXPECT_EQ(e.type, a.type);
    EXPECT_EQ(e.start, a.start);
    EXPECT_EQ(e.min, a.min);
    EXPECT_EQ(e.decay_episodes, a.decay_episodes);
    EXPECT_EQ(e.decay_rate, a.decay_rate);
    EXPECT_EQ(e.log_divisor, a.log_divisor);
  }
  EXPECT_EQ("", learningChangesText(expected, actual));
}

// What the controller reads from a message as the state, with the sim's default pose (readings
// and state one to one): readingsFromJointState, velocities required.
Reading<CartPoleState> readState(const sensor_msgs::JointState& msg, const std::string& cart_joint = "cart_joint",
                                 const std::string& pole_joint = "pole_joint")
{
  const Reading<JointReadings> read = readingsFromJointState(msg, cart_joint, pole_joint);
  if (!read)
    return {std::nullopt, read.refusal};
  if (!read.value->cart_velocity || !read.value->pole_velocity)
    return {std::nullopt, "no velocities"};
  return {CartPoleState(read.value->cart_position, *read.value->cart_velocity, read.value->pole_position,
                        *read.value->pole_velocity),
          ""};
}
}  // namespace

// ---- joint_states: sim -> controller

TEST(JointStateConversion, TheControllerReadsExactlyTheStateTheSimPublished)
{
  const CartPoleState state(-1.25, 0.5, 0.1234567890123, -2.0);
  const sensor_msgs::JointState msg = jointStateFromState(state, 7.5, stampAt(123456789012));
  EXPECT_EQ((std::vector<std::string>{"cart_joint", "pole_joint"}), msg.name);
  EXPECT_EQ((std::vector<double>{-1.25, 0.1234567890123}), msg.position);
  EXPECT_EQ((std::vector<double>{0.5, -2.0}), msg.velocity);
  EXPECT_EQ((std::vector<double>{7.5, 0.0}), msg.effort);  // the pole is not actuated
  EXPECT_EQ(123456789012u, msg.header.stamp.toNSec());

  const Reading<CartPoleState> read = readState(msg);
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_EQ("", read.refusal);
  EXPECT_EQ(state, *read.value);
}

TEST(JointStateConversion, JointsAreFoundByNameInAnyOrderAmongOthers)
{
  // A robot's joint_states: extra joints, the pole before the cart, no efforts.
  const sensor_msgs::JointState msg =
      joints({"wheel", "pole_joint", "gripper", "cart_joint"}, {9.0, 0.2, 8.0, 1.5}, {7.0, -0.3, 6.0, 0.4});
  const Reading<CartPoleState> read = readState(msg);
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_EQ(CartPoleState(1.5, 0.4, 0.2, -0.3), *read.value);
}

TEST(JointStateConversion, OtherJointNamesAreTakenAsGiven)
{
  const sensor_msgs::JointState msg = joints({"cart_to_pole", "slider_to_cart"}, {0.1, 2.0}, {0.3, 4.0});
  const Reading<CartPoleState> read = readState(msg, "slider_to_cart", "cart_to_pole");
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_EQ(CartPoleState(2.0, 4.0, 0.1, 0.3), *read.value);

  const Reading<CartPoleState> defaults = readState(msg);
  EXPECT_FALSE(defaults);
  EXPECT_EQ("dropped joint_states without cart_joint", defaults.refusal);
  EXPECT_EQ("dropped joint_states without pole_joint", readState(msg, "slider_to_cart", "pole_joint").refusal);
}

TEST(JointStateConversion, AMissingJointIsRefusedNamingIt)
{
  const Reading<CartPoleState> no_pole = readState(joints({"cart_joint", "wheel"}, {1, 2}, {3, 4}));
  EXPECT_FALSE(no_pole);
  EXPECT_FALSE(no_pole.value.has_value());
  EXPECT_EQ("dropped joint_states without pole_joint", no_pole.refusal);
  EXPECT_EQ("dropped joint_states without cart_joint", readState(joints({"pole_joint"}, {1}, {2})).refusal);
  EXPECT_EQ("dropped joint_states without cart_joint", readState(joints({}, {}, {})).refusal);
}

TEST(JointStateConversion, SizesThatDoNotMatchTheNamesAreRefused)
{
  EXPECT_EQ("dropped joint_states with 2 names but 1 positions and 2 velocities",
            readState(joints({"cart_joint", "pole_joint"}, {1}, {2, 3})).refusal);
  EXPECT_EQ("dropped joint_states with 2 names but 2 positions and 1 velocities",
            readState(joints({"pole_joint", "cart_joint"}, {1, 2}, {3})).refusal);
  // One value too many is no better than one too few: which joint it belongs to is unknown.
  EXPECT_EQ("dropped joint_states with 2 names but 3 positions and 2 velocities",
            readState(joints({"cart_joint", "pole_joint"}, {1, 2, 3}, {4, 5})).refusal);
}

TEST(JointStateConversion, NonFiniteValuesOfTheTwoJointsAreRefusedOthersNot)
{
  const std::string refusal = "dropped joint_states with a non-finite position or velocity";
  EXPECT_EQ(refusal, readState(joints({"cart_joint", "pole_joint"}, {kNaN, 0}, {0, 0})).refusal);
  EXPECT_EQ(refusal, readState(joints({"cart_joint", "pole_joint"}, {0, 0}, {0, -kInf})).refusal);
  EXPECT_EQ(refusal, readState(joints({"pole_joint", "cart_joint"}, {kInf, 0}, {0, 0})).refusal);
  EXPECT_FALSE(readState(joints({"cart_joint", "pole_joint"}, {0, 0}, {kNaN, 0})));
  // A broken sensor on a joint the controller does not use stops nothing.
  const Reading<CartPoleState> read =
      readState(joints({"cart_joint", "wheel", "pole_joint"}, {0.5, kNaN, 0.1}, {0.2, kInf, 0.3}));
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_EQ(CartPoleState(0.5, 0.2, 0.1, 0.3), *read.value);
}

TEST(JointStateConversion, OtherJointNamesArePublishedAsGiven)
{
  const sensor_msgs::JointState msg =
      jointStateFromState(CartPoleState(1, 2, 3, 4), 0.0, ros::Time(), "slider_to_cart", "cart_to_pole");
  EXPECT_EQ((std::vector<std::string>{"slider_to_cart", "cart_to_pole"}), msg.name);
  EXPECT_EQ(CartPoleState(1, 2, 3, 4), *readState(msg, "slider_to_cart", "cart_to_pole").value);
}

// ---- joint_command: controller -> sim

TEST(JointStateConversion, AnyCartPolesReadingsAreFoundByNameAndVelocitiesMayBeMissing)
{
  // gym-gazebo's names among other joints, the pole first.
  const Reading<JointReadings> read =
      readingsFromJointState(joints({"wheel", "cart_to_pole", "slider_to_cart"}, {9.0, 6.4, 0.5}, {1.0, 0.2, -0.3}),
                             "slider_to_cart", "cart_to_pole");
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_EQ(0.5, read.value->cart_position);
  EXPECT_EQ(6.4, read.value->pole_position);  // as read: the core wraps it
  EXPECT_EQ(-0.3, read.value->cart_velocity);
  EXPECT_EQ(0.2, read.value->pole_velocity);
  // A position-only driver: no velocity array at all is taken, a partial one is not.
  const Reading<JointReadings> positions =
      readingsFromJointState(joints({"cart_joint", "pole_joint"}, {1.0, 2.0}, {}), "cart_joint", "pole_joint");
  ASSERT_TRUE(positions) << positions.refusal;
  EXPECT_FALSE(positions.value->cart_velocity.has_value());
  EXPECT_FALSE(positions.value->pole_velocity.has_value());
  EXPECT_EQ("dropped joint_states with 2 names but 2 positions and 1 velocities",
            readingsFromJointState(joints({"cart_joint", "pole_joint"}, {1.0, 2.0}, {3.0}), "cart_joint", "pole_joint")
                .refusal);
  EXPECT_EQ(
      "dropped joint_states without foot_joint",
      readingsFromJointState(joints({"cart_joint", "pole_joint"}, {1.0, 2.0}, {}), "foot_joint", "pole_joint").refusal);
  EXPECT_FALSE(
      readingsFromJointState(joints({"cart_joint", "pole_joint"}, {kNaN, 2.0}, {}), "cart_joint", "pole_joint"));
}

TEST(CommandConversion, Float64CommandsCarryTheEffortInTheCartsSlot)
{
  EXPECT_EQ(-7.5, float64Command(-7.5).data);
  const std_msgs::Float64MultiArray group = float64ArrayCommand(3.0, 1, 3);
  EXPECT_EQ((std::vector<double>{0.0, 3.0, 0.0}), group.data);
  EXPECT_EQ((std::vector<double>{-2.0}), float64ArrayCommand(-2.0, 0, 1).data);
  const sensor_msgs::JointState named = commandMessage(4.0, stampAt(20000000), "cartJoint");
  EXPECT_EQ(std::vector<std::string>{"cartJoint"}, named.name);
}

TEST(JointStateConversion, ASimPosingAsAPositionOnlyRobotPublishesNoVelocities)
{
  const JointReadings r{0.5, 6.4, std::nullopt, std::nullopt};
  const sensor_msgs::JointState msg =
      jointStateFromReadings(r, 2.0, stampAt(20000000), "slider_to_cart", "cart_to_pole");
  EXPECT_EQ((std::vector<std::string>{"slider_to_cart", "cart_to_pole"}), msg.name);
  EXPECT_EQ((std::vector<double>{0.5, 6.4}), msg.position);
  EXPECT_TRUE(msg.velocity.empty());
  const Reading<JointReadings> read = readingsFromJointState(msg, "slider_to_cart", "cart_to_pole");
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_FALSE(read.value->cart_velocity.has_value());
}

TEST(CommandConversion, TheSimReadsTheEffortAndStampTheControllerSent)
{
  const ros::Time state_stamp = stampAt(5000000020);
  const sensor_msgs::JointState msg = commandMessage(-10.0, state_stamp);
  EXPECT_EQ(std::vector<std::string>{"cart_joint"}, msg.name);
  EXPECT_EQ(std::vector<double>{-10.0}, msg.effort);
  EXPECT_TRUE(msg.position.empty());
  EXPECT_TRUE(msg.velocity.empty());
  EXPECT_EQ(state_stamp, msg.header.stamp);  // the stamp of the state it answers

  const Reading<double> read = effortFromCommand(msg);
  ASSERT_TRUE(read) << read.refusal;
  EXPECT_EQ(-10.0, *read.value);
  // Unstamped states are answered unstamped.
  EXPECT_TRUE(commandMessage(3.0, ros::Time()).header.stamp.isZero());
  EXPECT_EQ(std::vector<std::string>{"slider_to_cart"}, commandMessage(1.0, state_stamp, "slider_to_cart").name);
}

TEST(CommandConversion, TheCartsEffortIsFoundAmongOtherJoints)
{
  sensor_msgs::JointState msg;
  msg.name = {"pole_joint", "cart_joint"};
  msg.effort = {1.0, 2.5};
  EXPECT_EQ(2.5, *effortFromCommand(msg).value);
  EXPECT_EQ(1.0, *effortFromCommand(msg, "pole_joint").value);
}

TEST(CommandConversion, ACommandWithoutAnEffortForTheCartIsRefused)
{
  sensor_msgs::JointState msg;
  msg.name = {"pole_joint"};
  msg.effort = {1.0};
  const Reading<double> wrong_joint = effortFromCommand(msg);
  EXPECT_FALSE(wrong_joint);
  EXPECT_EQ("dropped a joint_command without an effort for cart_joint (names: 1, efforts: 1)", wrong_joint.refusal);

  msg.name = {"cart_joint"};
  msg.effort.clear();
  msg.position = {1.0};  // a position is not an effort
  EXPECT_EQ("dropped a joint_command without an effort for cart_joint (names: 1, efforts: 0)",
            effortFromCommand(msg).refusal);
  msg.effort = {1.0, 2.0};
  EXPECT_EQ("dropped a joint_command without an effort for cart_joint (names: 1, efforts: 2)",
            effortFromCommand(msg).refusal);
  EXPECT_EQ("dropped a joint_command without an effort for slider_to_cart (names: 1, efforts: 2)",
            effortFromCommand(msg, "slider_to_cart").refusal);
}

TEST(CommandConversion, TheEffortComesAsSentTheSimJudgesIt)
{
  // Clamping and refusing NaN are the sim's, with its limit and its own warning.
  EXPECT_EQ(55.0, *effortFromCommand(commandMessage(55.0, ros::Time())).value);
  const Reading<double> nan = effortFromCommand(commandMessage(kNaN, ros::Time()));
  ASSERT_TRUE(nan);
  EXPECT_TRUE(std::isnan(*nan.value));
}

// ---- TF

TEST(TransformConversion, TheCartMovesAlongItsTrackAndThePoleTiltsTowardPlusX)
{
  const double theta = 0.3;
  const ros::Time stamp = stampAt(42000000000);
  const auto tf = transformsFromState(CartPoleState(0.7, 1.0, theta, 2.0), -1.5, stamp, "map", "cart_1", "pole_1");
  ASSERT_EQ(2u, tf.size());
  const geometry_msgs::TransformStamped& cart = tf[0];
  EXPECT_EQ("map", cart.header.frame_id);
  EXPECT_EQ("cart_1", cart.child_frame_id);
  EXPECT_EQ(stamp, cart.header.stamp);
  EXPECT_EQ(0.7, cart.transform.translation.x);
  EXPECT_EQ(-1.5, cart.transform.translation.y);
  EXPECT_EQ(0.0, cart.transform.translation.z);
  EXPECT_EQ(1.0, cart.transform.rotation.w);

  const geometry_msgs::TransformStamped& pole = tf[1];
  EXPECT_EQ("cart_1", pole.header.frame_id);
  EXPECT_EQ("pole_1", pole.child_frame_id);
  EXPECT_EQ(stamp, pole.header.stamp);
  EXPECT_EQ(0.0, pole.transform.translation.x);
  // The pole's axis (+z in its frame) seen from the cart: (sin theta, 0, cos theta).
  const geometry_msgs::Quaternion& q = pole.transform.rotation;
  EXPECT_NEAR(1.0, q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1e-15);
  EXPECT_NEAR(std::sin(theta), 2.0 * (q.x * q.z + q.w * q.y), 1e-15);
  EXPECT_NEAR(0.0, 2.0 * (q.y * q.z - q.w * q.x), 1e-15);
  EXPECT_NEAR(std::cos(theta), 1.0 - 2.0 * (q.x * q.x + q.y * q.y), 1e-15);
}

// ---- episode_stats

TEST(EpisodeStatsConversion, TheLearnersTopicCountsAllRobotsARobotsTopicItsOwn)
{
  EpisodeSummary s;
  s.episode = 41;
  s.steps = 137;
  s.episode_return = 137.0;
  s.mean_return_window = 88.5;
  s.epsilon = 0.3;
  s.alpha = 0.4;
  s.gamma = 0.97;
  s.terminated = true;
  s.truncated = false;
  s.solved = true;
  s.total_steps = 9001;
  s.robot = 2;
  s.robot_episode = 13;
  s.robot_mean_return_window = 99.25;
  s.robot_total_steps = 3003;
  const ros::Time stamp = stampAt(77000000001);

  const EpisodeStats learner = learnerEpisodeStats(s, "robot_2", stamp, 1234.5);
  const EpisodeStats robot = robotEpisodeStats(s, "robot_2", stamp, 321.0);
  EXPECT_EQ(41u, learner.episode);
  EXPECT_EQ(88.5, learner.mean_return_100);
  EXPECT_EQ(9001u, learner.total_steps);
  EXPECT_EQ(1234.5, learner.steps_per_second);
  EXPECT_EQ(13u, robot.episode);
  EXPECT_EQ(99.25, robot.mean_return_100);
  EXPECT_EQ(3003u, robot.total_steps);
  EXPECT_EQ(321.0, robot.steps_per_second);
  // The episode itself is the same on both topics.
  for (const EpisodeStats& stats : {learner, robot})
  {
    EXPECT_EQ(stamp, stats.header.stamp);
    EXPECT_EQ("robot_2", stats.robot);
    EXPECT_EQ(137u, stats.steps);
    EXPECT_EQ(137.0, stats.episode_return);
    EXPECT_EQ(0.3, stats.epsilon);
    EXPECT_EQ(0.4, stats.alpha);
    EXPECT_EQ(0.97, stats.gamma);
    EXPECT_TRUE(stats.terminated);
    EXPECT_FALSE(stats.truncated);
    EXPECT_TRUE(stats.solved);  // over all robots, on either topic
  }
  EXPECT_EQ("", learnerEpisodeStats(s, "", stamp, 0.0).robot);
}

// ---- live tuning: the server's fields <-> the core's settings

TEST(LearningConfigConversion, EveryFieldGoesToTheServerAndBack)
{
  const LearningSettings settings = unusualSettings();
  const LearningConfig c = toConfig(settings);
  EXPECT_EQ(0.91, c.gamma);
  EXPECT_EQ(0.0, c.epsilon_override);
  EXPECT_EQ(0.25, c.alpha_override);
  EXPECT_EQ("exponential", c.epsilon_schedule);
  EXPECT_EQ(0.8, c.epsilon_start);
  EXPECT_EQ(0.04, c.epsilon_min);
  EXPECT_EQ(321.0, c.epsilon_decay_episodes);
  EXPECT_EQ(0.97, c.epsilon_decay_rate);
  EXPECT_EQ(12.0, c.epsilon_log_divisor);
  EXPECT_EQ("linear", c.alpha_schedule);
  EXPECT_EQ(0.6, c.alpha_start);
  EXPECT_EQ(0.07, c.alpha_min);
  EXPECT_EQ(77.0, c.alpha_decay_episodes);
  EXPECT_EQ(0.93, c.alpha_decay_rate);
  EXPECT_EQ(18.0, c.alpha_log_divisor);

  LearningSettings back;  // the defaults: every field must be overwritten
  EXPECT_EQ("", fromConfig(c, back));
  expectSameSettings(settings, back);
}

TEST(LearningConfigConversion, TheServerStartsFromTheRunningConfigurationNotTheCfgDefaults)
{
  // (Was checked in live_tuning.test on the running controller: learning/ of its launch.)
  AgentParams agent;
  agent.gamma = 0.98;
  agent.epsilon.type = ScheduleType::Log;
  agent.epsilon.min = 0.02;
  const LearningConfig c = toConfig(LearningSettings::of(agent));
  EXPECT_EQ(0.98, c.gamma);
  EXPECT_EQ("log", c.epsilon_schedule);
  EXPECT_EQ(0.02, c.epsilon_min);
  EXPECT_NE(LearningConfig::__getDefault__().gamma, c.gamma);
  // No override: the server shows -1.
  EXPECT_EQ(-1.0, c.epsilon_override);
  EXPECT_EQ(-1.0, c.alpha_override);
}

TEST(LearningConfigConversion, AnyNegativeOverrideFollowsTheScheduleZeroIsGreedy)
{
  LearningConfig c = toConfig(unusualSettings());
  c.epsilon_override = -0.5;
  c.alpha_override = -1.0;
  LearningSettings s = unusualSettings();
  EXPECT_EQ("", fromConfig(c, s));
  EXPECT_FALSE(s.epsilon_override.has_value());
  EXPECT_FALSE(s.alpha_override.has_value());
  EXPECT_EQ(-1.0, toConfig(s).epsilon_override);  // shown as -1 from then on

  c.epsilon_override = 0.0;
  c.alpha_override = 1.0;
  EXPECT_EQ("", fromConfig(c, s));
  EXPECT_EQ(0.0, s.epsilon_override.value());
  EXPECT_EQ(1.0, s.alpha_override.value());
}

TEST(LearningConfigConversion, AnUnknownScheduleIsRefusedWithTheServersFieldName)
{
  const LearningSettings in_use = unusualSettings();
  LearningConfig c = toConfig(in_use);
  c.alpha_schedule = "cosine";
  LearningSettings s = in_use;
  const std::string error = fromConfig(c, s);
  EXPECT_EQ(0u, error.find("alpha_schedule = 'cosine' is not allowed (")) << error;
  EXPECT_EQ(in_use.alpha.type, s.alpha.type);  // left as it was

  c = toConfig(in_use);
  c.epsilon_schedule = "";
  EXPECT_EQ(0u, fromConfig(c, s).find("epsilon_schedule = '' is not allowed (")) << fromConfig(c, s);
  EXPECT_EQ(in_use.epsilon.type, s.epsilon.type);
}

TEST(LearningConfigConversion, TheCoresFieldNamesBecomeTheServers)
{
  EXPECT_EQ("epsilon_min = 0.9 is not allowed (must be in [0, start = 0.5])",
            asServerField("epsilon/min = 0.9 is not allowed (must be in [0, start = 0.5])"));
  EXPECT_EQ("alpha_log_divisor = 0 is not allowed", asServerField("alpha/log_divisor = 0 is not allowed"));
  // Only a slash in the field's name changes.
  EXPECT_EQ("gamma = 2 is not allowed (must be in [0, 1]/x)",
            asServerField("gamma = 2 is not allowed (must be in [0, 1]/x)"));
  EXPECT_EQ("alpha_override = -0.5 is not allowed", asServerField("alpha_override = -0.5 is not allowed"));
  EXPECT_EQ("", asServerField(""));
}

TEST(ServiceConversion, TheAnswerFillsTheResponseAndItsLinesAreReturned)
{
  struct
  {
    bool success = true;
    std::string message = "saved";
    LogLines log = {{LogLine::Level::Info, "saved 3 episodes"}};
  } answer;
  SaveQTable::Response response;
  const LogLines& log = toResponse(answer, response);
  EXPECT_TRUE(response.success);
  EXPECT_EQ("saved", response.message);
  ASSERT_EQ(1u, log.size());
  EXPECT_EQ("saved 3 episodes", log[0].text);
}

// The keys the controller lets pass on its private namespace and reads there are the cfg's fields,
// all of them, in its order.
TEST(LearningConfigConversion, TheKeysAreTheCfgsFields)
{
  std::vector<std::string> cfg;
  for (const auto& param : LearningConfig::__getParamDescriptions__())
    cfg.push_back(param->name);
  EXPECT_EQ(cfg, learningConfigKeys());
}

namespace
{
// Parameters as a map, the server's fields only (numbers and strings).
class FieldSource : public ParameterSource
{
public:
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> texts;
  bool get(const std::string& key, double& value) const override
  {
    if (texts.count(key) != 0)
      throw ConfigError(key + " must be a number");
    return find(numbers, key, value);
  }
  bool get(const std::string&, std::int64_t&) const override
  {
    return false;
  }
  bool get(const std::string&, bool&) const override
  {
    return false;
  }
  bool get(const std::string& key, std::string& value) const override
  {
    return find(texts, key, value);
  }
  bool get(const std::string&, std::vector<double>&) const override
  {
    return false;
  }
  bool get(const std::string&, std::vector<std::string>&) const override
  {
    return false;
  }
  std::vector<std::string> keysUnder(const std::string&) const override
  {
    return {};
  }
  std::string origin() const override
  {
    return "test";
  }

private:
  template <typename T>
  static bool find(const std::map<std::string, T>& values, const std::string& key, T& value)
  {
    const auto it = values.find(key);
    if (it == values.end())
      return false;
    value = it->second;
    return true;
  }
};
}  // namespace

TEST(LearningConfigConversion, WhatAnEarlierServerLeftReplacesOnlyTheFieldsPresent)
{
  const LearningSettings in_use = unusualSettings();
  EXPECT_TRUE(liveTuningReplacedLog(learningSettingsLeft(FieldSource(), in_use), in_use).empty())
      << "nothing left: nothing replaced";

  FieldSource left;
  left.numbers["gamma"] = 0.5;
  left.numbers["alpha_min"] = 0.0125;
  left.numbers["epsilon_override"] = -1.0;
  left.texts["epsilon_schedule"] = "constant";
  left.texts["alpha_decay_rate"] = "fast";  // a wrong type: left as it was
  const LearningSettings read = learningSettingsLeft(left, in_use);
  EXPECT_EQ(0.5, read.gamma);
  EXPECT_EQ(0.0125, read.alpha.min);
  EXPECT_FALSE(read.epsilon_override);
  EXPECT_EQ(ScheduleType::Constant, read.epsilon.type);
  EXPECT_EQ(in_use.alpha.decay_rate, read.alpha.decay_rate);
  EXPECT_EQ(in_use.epsilon.min, read.epsilon.min);
  EXPECT_EQ(in_use.alpha.type, read.alpha.type);
  EXPECT_FALSE(liveTuningReplacedLog(read, in_use).empty());
}

// What onReconfigure does with a client's change, without the server: the change as the node
// announces it, a refusal in the server's names, and the values it then answers with. (The
// texts were checked in live_tuning.test on the running controller; the rostest keeps the wiring.)
TEST(LearningConfigConversion, AClientsChangeIsAnnouncedARefusedOneUndoneInTheServersNames)
{
  AgentParams agent;
  agent.gamma = 0.98;
  TrainingSession session(TaskParams(), agent, 0);
  const LearningSettings in_use = session.learningSettings();

  LearningConfig change = toConfig(in_use);
  change.epsilon_override = 0.0;
  change.alpha_override = 0.2;
  change.gamma = 0.95;
  LearningSettings wanted = in_use;
  ASSERT_EQ("", fromConfig(change, wanted));
  EXPECT_EQ("epsilon_override none -> 0, alpha_override none -> 0.2, gamma 0.98 -> 0.95",
            learningChangesText(in_use, wanted));
  ASSERT_EQ("", session.setLearning(wanted));

  // min above start: the whole change is refused, gamma with it.
  const LearningSettings applied = session.learningSettings();
  LearningConfig bad = toConfig(applied);
  bad.epsilon_start = 0.5;
  bad.epsilon_min = 0.9;
  bad.gamma = 0.9;
  LearningSettings refused = applied;
  ASSERT_EQ("", fromConfig(bad, refused));
  const std::string error = session.setLearning(refused);
  EXPECT_EQ(0u, asServerField(error).find("epsilon_min = 0.9 is not allowed")) << error;
  const LearningConfig answered = toConfig(session.learningSettings());
  EXPECT_EQ(applied.epsilon.start, answered.epsilon_start);
  EXPECT_EQ(applied.epsilon.min, answered.epsilon_min);
  EXPECT_EQ(0.95, answered.gamma);
  EXPECT_EQ(0.0, answered.epsilon_override);
  EXPECT_EQ(0.2, answered.alpha_override);
}

TEST(LearningConfigConversion, BackToTheSchedulesTheyResumeAtTheEpisodeCount)
{
  // (Was checked in live_tuning.test: the episodes after a client set both overrides to -1.)
  TrainingSession session(TaskParams(), AgentParams(), 0);
  LearningSettings s = session.learningSettings();
  s.epsilon_override = 0.0;
  ASSERT_EQ("", session.setLearning(s));
  for (int i = 0; i < 30; ++i)
  {
    session.beginEpisode(CartPoleState::Zero());
    session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));  // falls at once
  }
  ASSERT_EQ(0.0, session.lastEpisode().epsilon);

  LearningConfig back = toConfig(session.learningSettings());
  back.epsilon_override = -1.0;
  LearningSettings wanted = session.learningSettings();
  ASSERT_EQ("", fromConfig(back, wanted));
  ASSERT_EQ("", session.setLearning(wanted));
  session.beginEpisode(CartPoleState::Zero());
  session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));
  const double expected = Schedule(AgentParams().epsilon).value(30);
  EXPECT_GT(expected, 0.0);
  EXPECT_DOUBLE_EQ(expected, session.lastEpisode().epsilon);
}

// The loggers of node instances: named after each node, and apart even when one line of code logs
// for both (ROS_*_NAMED would keep the first name it met there).
TEST(NodeLogger, EveryInstanceHasALoggerOfItsOwnUnderItsType)
{
  EXPECT_EQ("cartpole_sim.robot_1.cartpole_sim", nodeLogger("cartpole_sim", "/robot_1/cartpole_sim"));
  EXPECT_EQ("qlearning_controller.cartpole.qlearning_controller",
            nodeLogger("qlearning_controller", "/cartpole/qlearning_controller"));
  EXPECT_EQ("cartpole_sim", nodeLogger("cartpole_sim", ""));

  struct Lines : ros::console::LogAppender
  {
    std::vector<std::string> texts;
    void log(ros::console::Level, const char* str, const char*, const char*, int) override
    {
      texts.push_back(str);
    }
  };
  // Registered for the rest of the process, never deregistered: deregister_appender crashes with
  // Debian 11's rosconsole 1.14.3 on log4cxx 0.11 (a segmentation fault, reproduced there).
  static Lines* const lines = [] {
    auto* appender = new Lines;
    ros::console::register_appender(appender);
    return appender;
  }();
  lines->texts.clear();
  ros::console::set_logger_level(std::string(ROSCONSOLE_NAME_PREFIX) + ".cartpole_sim.a.cartpole_sim",
                                 ros::console::levels::Error);
  ros::console::notifyLoggerLevelsChanged();
  for (const std::string name : {"/a/cartpole_sim", "/b/cartpole_sim"})
    logLine(nodeLogger("cartpole_sim", name), LogLine::Level::Warn, name);
  EXPECT_EQ(std::vector<std::string>{"/b/cartpole_sim"}, lines->texts)
      << "the first sim's logger is set to errors only";
}
