// qlearning_controller's services and input checks, as wiring: save/load round trip through the
// services; a refused load answered as such, the live table unchanged and training going on;
// bad joint_states dropped; a silent sim reported. What a service decides (paths that escape the
// table folder, bad files of every kind, which table a load leaves) is RunApplicationTest's,
// FileAccessTest's and QTableFileTest's (application_tests, io_tests, learning_tests).
#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/LoadQTable.h"
#include "cartpole_qlearning/SaveQTable.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace fs = std::filesystem;
using namespace cartpole_qlearning;

using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::spinUntil;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRoot("root");

std::string root()
{
  return kRoot.path();
}

SaveQTable::Response save(const std::string& ns, const std::string& path)
{
  SaveQTable srv;
  srv.request.path = path;
  EXPECT_TRUE(ros::service::waitForService("/" + ns + "/qlearning_controller/save_q_table", ros::Duration(20)));
  EXPECT_TRUE(ros::service::call("/" + ns + "/qlearning_controller/save_q_table", srv));
  return srv.response;
}

LoadQTable::Response load(const std::string& ns, const std::string& path)
{
  LoadQTable srv;
  srv.request.path = path;
  EXPECT_TRUE(ros::service::waitForService("/" + ns + "/qlearning_controller/load_q_table", ros::Duration(20)));
  EXPECT_TRUE(ros::service::call("/" + ns + "/qlearning_controller/load_q_table", srv));
  return srv.response;
}

// A corrupt table in a controller's directory.
void writeBadFile(const std::string& dir)
{
  fs::create_directories(dir);
  std::ofstream(dir + "/corrupt.yaml") << "format: cartpole_qlearning/q_table\nversion: 1\nbins: [1, 1, 6, 12]\n"
                                       << "values: {{{ not yaml";
}

void expectRefused(const LoadQTable::Response& response, const std::string& what)
{
  EXPECT_FALSE(response.success) << what;
  EXPECT_NE(std::string::npos, response.message.find("unchanged")) << response.message;
}
}  // namespace

TEST(ControllerServices, EvaluateSaveLoadRoundTripAndRefusalsKeepTheTable)
{
  const std::string dir = root() + "/eval";
  writeBadFile(dir);
  // Greedy mode learns nothing, so the live table is observable through saves.
  const SaveQTable::Response first = save("eval", "");
  ASSERT_TRUE(first.success) << first.message;
  EXPECT_NE(std::string::npos, first.message.find(dir + "/q_table.yaml")) << first.message;
  const std::string before = fileText(dir + "/q_table.yaml");

  expectRefused(load("eval", "corrupt.yaml"), "corrupt file");
  const SaveQTable::Response escape = save("eval", "../escaped.yaml");
  EXPECT_FALSE(escape.success);
  EXPECT_NE(std::string::npos, escape.message.find("nothing written")) << escape.message;
  EXPECT_FALSE(fs::exists(root() + "/escaped.yaml"));

  ASSERT_TRUE(save("eval", "after_refusals.yaml").success);
  EXPECT_EQ(before, fileText(dir + "/after_refusals.yaml"));

  // A real table (trained offline, here: any valid table of the right shape) loads and is used.
  QTable table(DiscretiserParams(), {-10.0, 10.0});
  std::vector<double> values(table.values().size());
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = std::sin(static_cast<double>(i)) / 3.0;
  table.setValues(values);
  table.episodes = 42;
  saveQTableFile(table, dir + "/good.yaml");
  const LoadQTable::Response loaded = load("eval", "good.yaml");
  ASSERT_TRUE(loaded.success) << loaded.message;
  EXPECT_NE(std::string::npos, loaded.message.find("42 episodes")) << loaded.message;
  ASSERT_TRUE(save("eval", "sub/round_trip.yaml").success);
  EXPECT_EQ(fileText(dir + "/good.yaml"), fileText(dir + "/sub/round_trip.yaml"));
}

TEST(ControllerServices, TrainingGoesOnThroughRefusedLoads)
{
  const std::string dir = root() + "/train";
  writeBadFile(dir);
  ros::NodeHandle nh;
  std::uint64_t episodes = 0;
  std::vector<std::uint64_t> numbers;  // every episode_stats number, in order of arrival
  ros::Subscriber sub =
      nh.subscribe<EpisodeStats>("/train/episode_stats", 10000,
                                 boost::function<void(const EpisodeStatsConstPtr&)>([&](const EpisodeStatsConstPtr& m) {
                                   episodes = m->episode;
                                   numbers.push_back(m->episode);
                                 }));
  ASSERT_TRUE(spinUntil([&] { return episodes >= 5; }, 30.0)) << "training does not run";
  ASSERT_TRUE(save("train", "before.yaml").success);
  const QTable before = loadQTableFile(dir + "/before.yaml");

  expectRefused(load("train", "corrupt.yaml"), "corrupt");

  const std::uint64_t seen = episodes;
  ASSERT_TRUE(spinUntil([&] { return episodes >= seen + 20; }, 30.0)) << "training stopped after the refused load";
  ASSERT_TRUE(save("train", "after.yaml").success);
  const QTable after = loadQTableFile(dir + "/after.yaml");
  // Still the same table, trained further: same shape, counters grown from where they were.
  EXPECT_EQ("", before.shapeMismatch(after));
  EXPECT_GT(after.episodes, before.episodes);
  EXPECT_GT(after.steps, before.steps);

  // A valid load replaces the table: its counters restart from the loaded file's, below those
  // the live table had reached, and training goes on from there.
  ASSERT_TRUE(save("train", "latest.yaml").success);
  const QTable latest = loadQTableFile(dir + "/latest.yaml");
  const std::size_t before_load = numbers.size();
  ASSERT_TRUE(load("train", "before.yaml").success);
  ASSERT_TRUE(save("train", "reloaded.yaml").success);
  const QTable reloaded = loadQTableFile(dir + "/reloaded.yaml");
  // (Not compared with latest's steps: the services run on their own thread, so training goes on
  // between the load and this save, under ASan for more steps than latest was ahead. That the load
  // replaced the live table is shown race-free below: the episode numbers restart from its.)
  EXPECT_GE(reloaded.steps, before.steps);
  EXPECT_LE(before.steps, latest.steps);
  // The episode numbers go on from the loaded table's, so episode_stats and the saves agree: the
  // first episode to end after the load is one past the table's. (Looked for among all that
  // arrive, not in the last one seen: on a loaded machine a batch of them can pass at once. The
  // reports still arriving from before the load are numbered some 20 past it.)
  const std::uint64_t next = before.episodes + 1;
  ASSERT_TRUE(
      spinUntil([&] { return std::find(numbers.begin() + before_load, numbers.end(), next) != numbers.end(); }, 30.0))
      << "no episode_stats numbered " << next << " after a load of a table of " << before.episodes
      << " episodes; the last says " << episodes;
  ASSERT_TRUE(save("train", "counted.yaml").success);
  const std::uint64_t log = episodes;
  const QTable counted = loadQTableFile(dir + "/counted.yaml");
  EXPECT_GE(counted.episodes, log);
  // (A few more may end between the last message seen here and the save.)
  EXPECT_LE(counted.episodes, log + 20) << "the table's episodes and episode_stats disagree";
}

TEST(ControllerServices, BadJointStatesAreDroppedAndASilentSimIsReported)
{
  ros::NodeHandle nh;
  int commands = 0;
  int stops = 0;  // unstamped zeros: the controller stopping the cart, answering no state
  bool silent_reported = false;
  bool back_reported = false;
  ros::Subscriber effort = nh.subscribe<sensor_msgs::JointState>(
      "/alone/joint_command", 100,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        const bool stop = m->header.stamp.isZero() && m->effort.size() == 1 && m->effort[0] == 0.0;
        ++(stop ? stops : commands);
      }));
  ros::Subscriber log = nh.subscribe<rosgraph_msgs::Log>(
      "/rosout", 1000,
      boost::function<void(const rosgraph_msgs::LogConstPtr&)>([&](const rosgraph_msgs::LogConstPtr& m) {
        if (m->name != "/alone/qlearning_controller")
          return;
        silent_reported = silent_reported || m->msg.find("no joint_states") != std::string::npos;
        back_reported = back_reported || m->msg.find("joint_states are back") != std::string::npos;
      }));
  ros::Publisher states = nh.advertise<sensor_msgs::JointState>("/alone/joint_states", 10);
  ASSERT_TRUE(spinUntil([&] { return states.getNumSubscribers() > 0 && effort.getNumPublishers() > 0; }, 20.0));

  double stamp = 1.0;
  const auto make = [&](std::vector<std::string> names, std::vector<double> position, std::vector<double> velocity) {
    sensor_msgs::JointState msg;
    msg.header.stamp = ros::Time(stamp += 0.02);
    msg.name = std::move(names);
    msg.position = std::move(position);
    msg.velocity = std::move(velocity);
    return msg;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<sensor_msgs::JointState> bad = {
      make({"cart_joint"}, {0.0}, {0.0}),                          // pole_joint missing
      make({"cart_joint", "other"}, {0.0, 0.0}, {0.0, 0.0}),       // pole_joint missing
      make({"cart_joint", "pole_joint"}, {0.0}, {0.0, 0.0}),       // lengths differ
      make({"cart_joint", "pole_joint"}, {0.0, 0.0}, {0.0}),       // too few velocities (none: position-only)
      make({"cart_joint", "pole_joint"}, {nan, 0.0}, {0.0, 0.0}),  // NaN
      make({"cart_joint", "pole_joint"}, {0.0, 0.0}, {0.0, inf}),  // Inf
  };
  for (const auto& msg : bad)
    states.publish(msg);
  spinUntil([] { return false; }, 1.0);
  EXPECT_EQ(0, commands) << "a bad joint state was answered";
  ASSERT_TRUE(save("alone", "after_bad.yaml").success);
  const QTable table = loadQTableFile(root() + "/alone/after_bad.yaml");
  EXPECT_EQ(0u, table.steps);
  for (double v : table.values())
    EXPECT_EQ(0.0, v);

  // Joints found by name, in any order: a good state is answered.
  states.publish(make({"pole_joint", "cart_joint"}, {0.01, 0.0}, {0.0, 0.0}));
  EXPECT_TRUE(spinUntil([&] { return commands == 1; }, 10.0));

  // No sim in this namespace: after sim_timeout (1 s) of silence the controller says so, once,
  // and says so again when states come back.
  ASSERT_TRUE(spinUntil([&] { return silent_reported; }, 20.0)) << "no report of the silent sim";
  // ... and stops the cart, which may hold its last command (ros_control's forward controllers).
  // (At least one: the freshness guard's and the silence's stops may both come, a second zero
  // being harmless; the sanitized CI run of 2026-12-03 once saw this wait fail with '== 1'.)
  EXPECT_TRUE(spinUntil([&] { return stops >= 1; }, 5.0))
      << "no zero effort after the states stopped: " << stops << " stops, " << commands << " commands";
  states.publish(make({"cart_joint", "pole_joint"}, {0.0, 0.01}, {0.0, 0.0}));
  EXPECT_TRUE(spinUntil([&] { return back_reported; }, 10.0));
  EXPECT_TRUE(spinUntil([&] { return commands == 2; }, 10.0));
}

TEST(ControllerServices, EachStateIsAnsweredWithItsOwnStampAndLearntFromOnce)
{
  // The sim repeats a state whose answer it did not get; the controller answers a repeat again
  // (the same effort, the same stamp: the sim steps on one of them at most) and learns from it
  // only once. An older stamp (a replayed message) is dropped; the next new state is answered.
  ros::NodeHandle nh;
  std::vector<sensor_msgs::JointState> commands;
  ros::Subscriber command = nh.subscribe<sensor_msgs::JointState>(
      "/alone/joint_command", 100,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>(
          [&](const sensor_msgs::JointStateConstPtr& m) { commands.push_back(*m); }));
  ros::Publisher states = nh.advertise<sensor_msgs::JointState>("/alone/joint_states", 10);
  ASSERT_TRUE(spinUntil([&] { return states.getNumSubscribers() > 0 && command.getNumPublishers() > 0; }, 20.0));
  const auto steps = [](const std::string& name) {
    EXPECT_TRUE(save("alone", name).success);
    return loadQTableFile(root() + "/alone/" + name).steps;
  };

  sensor_msgs::JointState msg;
  msg.name = {"cart_joint", "pole_joint"};
  msg.position = {0.0, 0.02};
  msg.velocity = {0.0, 0.0};
  msg.header.stamp = ros::Time(100.0);  // later than anything the earlier tests sent
  states.publish(msg);
  ASSERT_TRUE(spinUntil([&] { return commands.size() == 1; }, 10.0)) << "a new state was not answered";
  const std::uint64_t learnt = steps("repeat_before.yaml");
  states.publish(msg);  // the same stamp again, as the sim repeats an unanswered state
  states.publish(msg);
  ASSERT_TRUE(spinUntil([&] { return commands.size() == 3; }, 10.0)) << "a repeated state was not answered again";
  for (const sensor_msgs::JointState& c : commands)
  {
    EXPECT_EQ(ros::Time(100.0), c.header.stamp) << "an answer must carry the stamp of the state it answers";
    ASSERT_EQ(std::vector<std::string>{"cart_joint"}, c.name);
    ASSERT_EQ(1u, c.effort.size());
    EXPECT_EQ(commands.front().effort, c.effort) << "a repeat was answered with another effort";
  }
  EXPECT_EQ(learnt, steps("repeat_after.yaml")) << "a repeated state was learnt from again";

  msg.header.stamp = ros::Time(99.98);  // older: a replayed message
  states.publish(msg);
  spinUntil([] { return false; }, 1.0);
  EXPECT_EQ(3u, commands.size()) << "an older state was answered";

  msg.header.stamp = ros::Time(100.02);
  msg.position[1] = 0.021;
  states.publish(msg);
  ASSERT_TRUE(spinUntil([&] { return commands.size() == 4; }, 10.0)) << "the next state was not answered";
  EXPECT_EQ(ros::Time(100.02), commands.back().header.stamp);
  EXPECT_EQ(learnt + 1, steps("next_after.yaml")) << "the transition into the new state was not learnt once";
}
