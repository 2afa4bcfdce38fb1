// robot.launch mode:=control load:=TABLE with a swing-up table, no config, no reset service
// (swingup_control.test): five minutes of the robot's time on the sim posing as a robot (lockstep:
// 30,000 decisions of 0.01 s), which starts the pole hanging and knocks it down with pushes now and
// then. What must hold whatever the table: the sim starts hanging; the controller never treats
// the pole past CartPole-v1's 12 degrees as a fall (it never commands 0 waiting for a person and
// goes on commanding efforts to the end); control_stats's time upright, swing-ups, falls and rail
// hits are what the robot's own states show (the test counts them from joint_states with the
// documented definitions); Ctrl-C leaves zero effort and a last line that says how it went. What
// must hold when the table can swing up at all (its greedy score, train_headless --evaluate, at
// least kSwingsUp): it swings the hanging pole up, the pushes knock it down at least twice, and
// every knock-down is swung up again (a pole still down at the end fell in its last kAllowedSwingUp
// seconds), and it is up more than half the time; a table at kSwingsUpWell, sooner and longer.
#include "cartpole_qlearning/ControlStats.h"

#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cartpole_qlearning::ControlStats;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::spinUntil;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");

// A table whose greedy score (the Suite's, the mean of 10 episodes of 1,000 steps) is at least this
// swings the hanging pole up and holds it for most of an episode: every knock is swung up again,
// within kAllowedSwingUp. config/swingup.yaml's tables (500,000 steps) score 805-851: seed 0's
// (851) took 10.5 s for its slowest of the pushes' knocks on Debian 12. An earlier config's seed 0
// (735) took 44 s on Debian 12, upright 75 % of the five minutes; trained and run on Debian 11,
// whose C library's sin and cos differ in their last bits (docs/testing.md), 116 s.
constexpr double kSwingsUp = 700.0;
constexpr double kAllowedSwingUp = 150.0;  // [s] from the knock to upright
// A table that scores as the Suite's published learners do (850): a knock swung up again within
// kAllowedSwingUpWell, the pole upright more than 70 % of the time.
constexpr double kSwingsUpWell = 850.0;
constexpr double kAllowedSwingUpWell = 20.0;  // [s]
// The definitions docs/nodes.md gives for control_stats.
constexpr double kUprightCos = 0.95;
constexpr double kHoldSeconds = 1.0;
constexpr double kRailLimit = 1.8;

struct Sample
{
  std::uint64_t stamp = 0;
  double x = 0.0;
  double theta = 0.0;
  double effort = 0.0;  // the force that acted during the step before it (a push included)
};

// What control_stats must say, counted from the robot's states the controller decided on (answered)
// up to (and with) the one stamped `until`.
struct Counted
{
  double seconds = 0.0;
  double upright_seconds = 0.0;
  std::uint64_t swing_ups = 0;
  std::uint64_t falls = 0;
  std::uint64_t rail_hits = 0;
  bool up = false;
  double last_fall_at = 0.0;
};

Counted count(const std::vector<Sample>& samples, const std::set<std::uint64_t>& answered, std::uint64_t until)
{
  Counted c;
  std::optional<std::uint64_t> last;
  std::optional<double> upright_since;
  bool at_end = false;
  bool first = true;
  for (const Sample& s : samples)
  {
    if (s.stamp > until || (last && s.stamp <= *last) || answered.count(s.stamp) == 0)
      continue;  // after the report, a repeat, or a state not decided on
    const double dt = last ? static_cast<double>(s.stamp - *last) * 1e-9 : 0.0;
    last = s.stamp;
    c.seconds += dt;
    const double up = std::cos(s.theta);
    if (up >= kUprightCos)
      c.upright_seconds += dt;
    const double from_end = kRailLimit - std::abs(s.x);
    if (!at_end && from_end <= 0.02)
    {
      at_end = true;
      ++c.rail_hits;
    }
    else if (at_end && from_end > 0.1)
      at_end = false;
    if (first && up >= kUprightCos)
      c.up = true;
    first = false;
    if (c.up)
    {
      if (up < 0.0)
      {
        c.up = false;
        ++c.falls;
        c.last_fall_at = c.seconds;
        upright_since.reset();
      }
      continue;
    }
    if (up < kUprightCos)
    {
      upright_since.reset();
      continue;
    }
    if (!upright_since)
      upright_since = c.seconds;
    if (c.seconds - *upright_since >= kHoldSeconds - 1e-9)
    {
      c.up = true;
      ++c.swing_ups;
    }
  }
  return c;
}
}  // namespace

TEST(SwingupControl, ATableSwingsAHangingPoleUpAndKeepsControllingThroughKnocksForFiveMinutes)
{
  const std::string home = kRosHome.path();
  ASSERT_FALSE(home.empty());
  fs::create_directories(home);
  int seed = 0;
  ros::param::get("~seed", seed);
  double push_force = 0.0;
  ros::param::get("~push_force", push_force);

  // The table: train_headless on config/swingup.yaml, not solved (its run folder keeps it).
  const auto trained = runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --config " + CARTPOLE_CONFIG_DIR +
                                  "/swingup.yaml --seed " + std::to_string(seed) + " --quiet --checkpoint-every 0");
  ASSERT_EQ(0, trained.status) << trained.output;
  std::string table;
  for (const auto& run : fs::directory_iterator(home + "/cartpole_qlearning/cartpole/runs"))
    table = (run.path() / "q_table.yaml").string();
  ASSERT_TRUE(fs::exists(table)) << trained.output;
  const auto evaluated = runCommand(std::string(TRAIN_HEADLESS) + " --evaluate " + table + " --episodes 10");
  ASSERT_EQ(0, evaluated.status) << evaluated.output;
  cartpole_qlearning::test::text_match::Groups score;
  ASSERT_TRUE(cartpole_qlearning::test::text_match::contains(evaluated.lastLine(), "mean_return=([0-9.-]+)", &score))
      << evaluated.output;
  const double table_score = std::stod(score[1]);
  const bool swings_up = table_score >= kSwingsUp;

  ros::NodeHandle nh;
  std::vector<ControlStats> reports;
  const ros::Subscriber stats = nh.subscribe<ControlStats>(
      "/cartpole/control_stats", 1000,
      boost::function<void(const cartpole_qlearning::ControlStatsConstPtr&)>(
          [&](const cartpole_qlearning::ControlStatsConstPtr& m) { reports.push_back(*m); }));
  std::vector<Sample> samples;
  const ros::Subscriber states = nh.subscribe<sensor_msgs::JointState>(
      "/cartpole/joint_states", 100000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        if (m->position.size() == 2 && m->effort.size() == 2)
          samples.push_back({m->header.stamp.toNSec(), m->position[0], m->position[1], m->effort[0]});
      }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  std::vector<std::pair<std::uint64_t, double>> commands;  // (the state answered, the effort)
  const ros::Subscriber command = nh.subscribe<sensor_msgs::JointState>(
      "/cartpole/joint_command", 100000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        if (!m->effort.empty())
          commands.emplace_back(m->header.stamp.toNSec(), m->effort[0]);
      }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ASSERT_TRUE(spinUntil([&] { return !samples.empty(); }, 10.0)) << "no joint_states from the sim";

  // The sim holds no command in lockstep: no freshness guard. A report each minute of robot time; the
  // motor's limit is the table's 10 N, as the robot's owner gives it. No reset service (robot.launch's
  // default): nobody stands the pole up.
  TrainLaunch launch(home, "control",
                     "mode:=control load:=" + table + " robot_lockstep:=true max_effort:=10 report_every:=60",
                     "robot.launch");
  ASSERT_TRUE(spinUntil([&] { return !reports.empty() && reports.back().seconds >= 300.0; }, 240.0))
      << reports.size() << " reports"
      << (reports.empty() ? "" : ", the last at " + std::to_string(reports.back().seconds)) << " s\n"
      << launch.output();
  const ControlStats at_five_minutes = reports.back();
  EXPECT_EQ(0, launch.interrupt(30.0)) << launch.output();
  spinUntil([&] { return false; }, 0.5);  // what was sent before the end arrives
  const std::string output = launch.output();

  // The sim ran the task's start: the pole hanging, as swingup.yaml's task starts it.
  EXPECT_LT(std::cos(samples.front().theta), -0.99) << samples.front().theta;
  // The pushes came (the sim's effort is the force that acted: the motor's at most 10 N, a push's more).
  std::size_t pushes = 0;
  for (const Sample& s : samples)
    pushes += std::abs(s.effort) > 10.5 && s.stamp <= at_five_minutes.header.stamp.toNSec() ? 1 : 0;
  EXPECT_GE(pushes, 2u) << "push_force " << push_force;

  // No fall in the CartPole-v1 sense: the controller never stopped to wait for a person, and it went on
  // commanding efforts in every minute, the pole hanging or not.
  EXPECT_NE(std::string::npos, output.find("never ends on the angle: a pole down is swung up again")) << output;
  EXPECT_EQ(std::string::npos, output.find("commanding 0 until")) << output;
  EXPECT_EQ(std::string::npos, output.find("someone has to stand it up")) << output;
  const std::uint64_t first = samples.front().stamp;
  for (int minute = 0; minute < 5; ++minute)
  {
    std::size_t pushing = 0;
    for (const auto& [stamp, effort] : commands)
      pushing +=
          effort != 0.0 && stamp >= first + minute * 60000000000ull && stamp < first + (minute + 1) * 60000000000ull
              ? 1
              : 0;
    EXPECT_GT(pushing, 100u) << "minute " << minute + 1 << ": the controller stopped driving the cart";
  }

  // control_stats is what the robot's states show: its time, its time upright (cos(theta) >= 0.95), its
  // swing-ups and falls by the angle, its arrivals at the rail's ends.
  std::set<std::uint64_t> answered;
  for (const auto& [stamp, effort] : commands)
    answered.insert(stamp);
  const Counted counted = count(samples, answered, at_five_minutes.header.stamp.toNSec());
  EXPECT_NEAR(counted.seconds, at_five_minutes.seconds, 1e-6);
  EXPECT_GT(at_five_minutes.seconds, 299.9);
  EXPECT_NEAR(counted.upright_seconds, at_five_minutes.upright_seconds, 1e-6);
  EXPECT_EQ(counted.swing_ups, at_five_minutes.swing_ups);
  EXPECT_EQ(counted.falls, at_five_minutes.falls);
  EXPECT_EQ(counted.rail_hits, at_five_minutes.rail_hits);
  EXPECT_LE(at_five_minutes.balanced_seconds, at_five_minutes.seconds);
  EXPECT_LE(at_five_minutes.longest_swing_up_seconds, at_five_minutes.seconds);
  // Every swing-up and every fall was said, and published as it happened.
  const auto said = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = output.find(what); at != std::string::npos; at = output.find(what, at + 1))
      ++n;
    return n;
  };
  // Ctrl-C: zero effort last, and the last line says how it went: as many swing-ups and falls as were
  // said, those of the five minutes and any since.
  ASSERT_FALSE(commands.empty());
  EXPECT_EQ(0.0, commands.back().second);
  cartpole_qlearning::test::text_match::Groups ended;
  ASSERT_TRUE(cartpole_qlearning::test::text_match::contains(
      output,
      "control ended: upright [0-9.]+ s of [0-9.]+ s \\(cos\\(theta\\) >= 0.95\\), ([0-9]+) swing-ups?.*, balanced "
      "[0-9.]+ "
      "s of [0-9.]+ s, the longest stretch [0-9.]+ s, ([0-9]+) falls?, [0-9]+ hits? of the rail's ends, 0 of [0-9]+ "
      "commands beyond the motor's 10 N",
      &ended))
      << output;
  EXPECT_EQ(std::stoull(ended[1]), said("control: swung the pole up in ")) << output;
  EXPECT_EQ(std::stoull(ended[2]), said("control: the pole fell after ")) << output;
  EXPECT_GE(std::stoull(ended[1]), at_five_minutes.swing_ups);
  EXPECT_GE(std::stoull(ended[2]), at_five_minutes.falls);

  std::printf(
      "five minutes of swing-up control, seed %d's table (greedy score %.1f): upright %.1f s, %llu "
      "swing-ups (the longest %.1f s), %llu falls, %zu pushes, %llu rail hits\n",
      seed, table_score, at_five_minutes.upright_seconds, static_cast<unsigned long long>(at_five_minutes.swing_ups),
      at_five_minutes.longest_swing_up_seconds, static_cast<unsigned long long>(at_five_minutes.falls), pushes,
      static_cast<unsigned long long>(at_five_minutes.rail_hits));
  if (!swings_up)
  {
    std::printf(
        "the table scores %.1f < %.0f: it cannot swing the pole up yet, so the test checks the protocol "
        "only\n",
        table_score, kSwingsUp);
    return;
  }
  // A table that swings up: the hanging pole comes up, the pushes knock it down at least twice, and each
  // knock is swung up again (one still down at the end fell within the last kAllowedSwingUp seconds).
  EXPECT_GE(at_five_minutes.falls, 2u) << "the pushes knocked the pole down fewer than twice";
  EXPECT_GE(at_five_minutes.swing_ups, at_five_minutes.falls) << "a knocked pole was not swung up again";
  if (!counted.up)
    EXPECT_GT(counted.last_fall_at, at_five_minutes.seconds - kAllowedSwingUp);
  else
    EXPECT_EQ(at_five_minutes.falls + 1, at_five_minutes.swing_ups);
  EXPECT_LE(at_five_minutes.longest_swing_up_seconds, kAllowedSwingUp);
  EXPECT_GT(at_five_minutes.upright_seconds, 0.5 * at_five_minutes.seconds);
  if (table_score >= kSwingsUpWell)
  {
    EXPECT_LE(at_five_minutes.longest_swing_up_seconds, kAllowedSwingUpWell);
    EXPECT_GT(at_five_minutes.upright_seconds, 0.7 * at_five_minutes.seconds);
  }
}
