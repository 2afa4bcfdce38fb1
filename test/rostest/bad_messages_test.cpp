// Bad messages at scale (issue 8, item 7). While cartpole_sim and qlearning_controller train in
// lockstep (bad_messages.test), this node sends the controller's joint_states and the sim's
// joint_command and cart_effort 1000 malformed messages of each kind, then floods each node in
// turn with them at 15 times the step rate it measured, for 2 s. What each node's sockets
// received, and how many of those its full subscriber queue dropped, is read from the node's
// bus statistics (getBusStats) and printed with the flood ratio. After each part it checks that
//   - both nodes are still the processes they were (XML-RPC getPid) and training goes on
//     (episode_stats keep coming, episode and total_steps growing);
//   - the sim never published a non-finite state or an applied effort beyond its limit, and
//     never stepped on a malformed command: each malformed command carries an effort of its own
//     (kind / 8 N; the controller's actions are +-10 N and a reset publishes 0), which the sim
//     would publish as the applied force of a step taken on it;
//   - the controller never took a state it must drop: each malformed state carries its kind in
//     the last three digits of its stamp's nanoseconds (the sim's stamps are multiples of 20 ms),
//     and an answer carries the stamp of the state it answers, episode_stats the stamp of the
//     state that ended the episode;
//   - the controller's table, saved through ~save_q_table and loaded back with the core's
//     loader, holds finite values only;
//   - each node warned a few times a second at most (on /rosout), not once per message.
// What is expected of finite but absurd values (1e308): a well-formed state with a new stamp is
// a state like any other (over ROS 1 nothing tells it from the sim's): the discretiser puts it
// in an edge bin, the task ends the episode when |x| or |theta| is beyond its threshold, and the
// state only selects a table row, so nothing non-finite can come of it. An effort of 1e308
// stamped with the pending state is a command like any other: the sim clamps it to its limit.
#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/SaveQTable.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include "ros_test_support.h"
#include "rostest_main.h"

#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <ros/xmlrpc_manager.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cartpole_qlearning::test::callNode;
using cartpole_qlearning::test::callNodeRaw;
using cartpole_qlearning::test::pidOf;
using cartpole_qlearning::test::spinUntil;

namespace
{
const std::string kNs = "/bad";
const std::string kSimNode = kNs + "/cartpole_sim";
const std::string kControllerNode = kNs + "/qlearning_controller";
constexpr std::uint64_t kTick = 20000000;  // [ns] physics/tau = 0.02 s: the sim's stamps are multiples of it
constexpr std::uint64_t kSecond = 1000000000;
constexpr double kEffortLimit = 10.0;  // physics/force_mag, the sim's default ~effort_limit
constexpr int kPerKind = 1000;
constexpr double kFloodSeconds = 2.0;
constexpr double kFloodFactor = 15.0;  // the flood's rate: this many times the normal step rate
constexpr double kWait = 60.0;         // generous: a loaded 2-core CI machine
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kHuge = 1e308;

// Malformed joint_states for the controller. The value is the marker in the stamp.
enum StateKind : int
{
  kUnknownNames = 1,   // two joints, neither cart_joint nor pole_joint
  kMissingJoint,       // cart_joint or pole_joint alone
  kEmpty,              // a default-constructed message: no names, no values, stamp 0
  kNamesVsPositions,   // 2 names, 1 or 3 positions
  kNamesVsVelocities,  // 2 names, 0 or 3 velocities
  kNaNPosition,
  kInfPosition,  // +Inf and -Inf in turn
  kNaNVelocity,
  kInfVelocity,
  kOlderStamp,       // well-formed, stamped older than the current state (each stamp once)
  kZeroStamp,        // well-formed, stamp 0 among stamped states
  kRepeatedStamp,    // well-formed, the stamp of the latest state again
  kOlderStampTwice,  // well-formed, the same older stamp twice in a row
  kHugeValues,       // +-1e308 in a position or a velocity, a new stamp
  kStateKindEnd
};
const char* const kStateKindNames[] = {"",
                                       "unknown joint names",
                                       "a missing joint",
                                       "empty message",
                                       "names vs positions lengths",
                                       "names vs velocities lengths",
                                       "NaN position",
                                       "+-Inf position",
                                       "NaN velocity",
                                       "+-Inf velocity",
                                       "stamp older than the current one",
                                       "stamp 0 among stamped states",
                                       "the current stamp again",
                                       "the same older stamp twice",
                                       "+-1e308 position or velocity"};
// Whether the controller may answer a state of this kind. A repeat is answered again (the same
// effort, the same stamp: the sim steps on one at most). The same older stamp twice is how a
// restarted sim looks (lockstep_protocol.h): the episode is abandoned and the state taken as a
// start. A huge but finite, well-formed state is a state.
bool mayBeAnswered(int kind)
{
  return kind == kRepeatedStamp || kind == kOlderStampTwice || kind == kHugeValues;
}

// Malformed commands for the sim (joint_command, and the last two on cart_effort).
enum CommandKind : int
{
  kWrongName = 21,    // pole_joint or cart instead of cart_joint
  kNoName,            // an effort without a name
  kNoEffort,          // cart_joint without an effort
  kNamesVsEfforts,    // 2 names and 1 effort, or 1 name and 2 efforts
  kNaNEffort,         // stamped with the latest state: only the value is wrong
  kInfEffort,         // +Inf and -Inf in turn
  kStaleStamp,        // 2 to 51 ticks older than the latest state
  kFutureStamp,       // 1000 s after the latest state
  kZeroStampCommand,  // stamp 0
  kHugeEffort,        // +-1e308, stamped with the latest state: clamped if it steps
  kNaNCartEffort,     // cart_effort NaN
  kInfCartEffort,     // cart_effort +-Inf
  kCommandKindEnd
};
const char* const kCommandKindNames[] = {
    "wrong joint name", "no name",        "no effort",       "names vs efforts lengths",
    "NaN effort",       "+-Inf effort",   "stale stamp",     "future stamp",
    "stamp 0",          "+-1e308 effort", "cart_effort NaN", "cart_effort +-Inf"};
double markerEffort(int kind)
{
  return kind / 8.0;  // 2.625 ... 4.0 N: never an action (+-10 N) nor a reset's 0
}

ros::Time timeOf(std::uint64_t ns)
{
  ros::Time t;
  t.fromNSec(ns);
  return t;
}

struct LogLine
{
  ros::WallTime at;
  std::string node;
  int level;
  std::string msg;
};

// Watches, on a thread of its own, what the nodes publish: the sim's states, the controller's
// commands, episode_stats and /rosout. This node's own messages on the same topics (delivered
// to it within the process) are told apart by their publisher.
class Observer
{
public:
  void onState(const ros::MessageEvent<sensor_msgs::JointState const>& event)
  {
    if (event.getPublisherName() != kSimNode)
      return;
    const sensor_msgs::JointState& msg = *event.getConstMessage();
    const std::lock_guard<std::mutex> lock(mutex_);
    ++sim_states_;
    latest_ = std::max<std::uint64_t>(latest_, msg.header.stamp.toNSec());
    const std::size_t n = msg.name.size();
    if (n != 2 || msg.name[0] != "cart_joint" || msg.name[1] != "pole_joint" || msg.position.size() != n ||
        msg.velocity.size() != n || msg.effort.size() != n)
    {
      problem("a malformed state from the sim");
      return;
    }
    for (const double v :
         {msg.position[0], msg.position[1], msg.velocity[0], msg.velocity[1], msg.effort[0], msg.effort[1]})
    {
      if (!std::isfinite(v))
      {
        ++sim_nonfinite_;
        std::ostringstream out;
        out << "a non-finite state from the sim: position [" << msg.position[0] << ", " << msg.position[1]
            << "], velocity [" << msg.velocity[0] << ", " << msg.velocity[1] << "], effort " << msg.effort[0];
        problem(out.str());
        return;
      }
    }
    const double effort = msg.effort[0];
    const int kind = static_cast<int>(std::lround(effort * 8.0));
    if (kind >= kWrongName && kind < kCommandKindEnd && markerEffort(kind) == effort)
      problem("the sim stepped on a malformed command (" + std::string(kCommandKindNames[kind - kWrongName]) +
              "): it applied its effort of " + std::to_string(effort) + " N");
    if (std::fabs(effort) > kEffortLimit)
      problem("the sim applied " + std::to_string(effort) + " N, beyond its limit");
  }

  void onCommand(const ros::MessageEvent<sensor_msgs::JointState const>& event)
  {
    if (event.getPublisherName() != kControllerNode)
      return;
    const sensor_msgs::JointState& msg = *event.getConstMessage();
    const std::lock_guard<std::mutex> lock(mutex_);
    ++commands_;
    if (msg.name != std::vector<std::string>{"cart_joint"} || msg.effort.size() != 1 || !std::isfinite(msg.effort[0]))
      problem("a malformed or non-finite command from the controller");
    const std::uint64_t stamp = msg.header.stamp.toNSec();
    // An unstamped zero answers no state: the controller stopping the cart (an episode's end).
    if (stamp == 0 && msg.effort.size() == 1 && msg.effort[0] == 0.0)
      return;
    if (stamp == 0)
      ++answered_unstamped_;
    else if (stamp % 1000 != 0)
      ++answered_[static_cast<int>(stamp % 1000)];
  }

  void onStats(const cartpole_qlearning::EpisodeStatsConstPtr& msg)
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stats_count_ > 0 && (msg->episode <= episode_ || msg->total_steps < total_steps_))
      problem("episode_stats went back: episode " + std::to_string(msg->episode) + " after " +
              std::to_string(episode_));
    // An episode_stats message is stamped with the state that ended the episode: a terminal state
    // (an infinite position, say) is not answered, but it ends an episode if it is taken.
    const std::uint64_t stamp = msg->header.stamp.toNSec();
    const int kind = static_cast<int>(stamp % 1000);
    if (stamp == 0 || (kind != 0 && (kind >= kStateKindEnd || !mayBeAnswered(kind))))
      problem("an episode ended on a state the controller must drop (" +
              std::string(stamp == 0             ? "stamp 0"
                          : kind < kStateKindEnd ? kStateKindNames[kind]
                                                 : "?") +
              ")");
    ++stats_count_;
    episode_ = msg->episode;
    total_steps_ = msg->total_steps;
  }

  void onLog(const rosgraph_msgs::LogConstPtr& msg)
  {
    if (msg->name != kSimNode && msg->name != kControllerNode)
      return;
    const std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back({ros::WallTime::now(), msg->name, static_cast<int>(msg->level), msg->msg});
  }

  std::uint64_t latest() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }
  std::uint64_t simStates() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return sim_states_;
  }
  std::uint32_t episode() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return episode_;
  }
  std::uint64_t totalSteps() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return total_steps_;
  }

  // Warnings and errors from a node that arrived since `since`.
  std::size_t warningsSince(const std::string& node, ros::WallTime since) const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<std::size_t>(std::count_if(logs_.begin(), logs_.end(), [&](const LogLine& line) {
      return line.node == node && line.at >= since && line.level >= rosgraph_msgs::Log::WARN;
    }));
  }

  // The warnings of a node since `since`, grouped by their text up to the first digit.
  std::string warningKinds(const std::string& node, ros::WallTime since) const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::map<std::string, std::size_t> kinds;
    for (const LogLine& line : logs_)
    {
      if (line.node == node && line.at >= since && line.level >= rosgraph_msgs::Log::WARN)
        ++kinds[line.msg.substr(0, std::min<std::size_t>(line.msg.find_first_of("0123456789"), 100))];
    }
    std::ostringstream out;
    for (const auto& [text, count] : kinds)
      out << "\n  " << count << " x '" << text << "...'";
    return out.str();
  }

  // Everything that must never happen, said in words ("" when nothing did).
  std::string violations() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream out;
    if (!problems_.empty())
      out << problem_count_ << " problems, the first: " << problems_.front() << "; ";
    for (const auto& [kind, count] : answered_)
    {
      if (kind < kStateKindEnd && !mayBeAnswered(kind))
        out << "the controller answered " << count << " states of a kind it must drop (" << kStateKindNames[kind]
            << "); ";
      if (kind >= kStateKindEnd)
        out << "the controller answered " << count << " states with an unknown marker " << kind << "; ";
    }
    if (answered_unstamped_ > 0)
      out << "the controller answered " << answered_unstamped_
          << " states stamped 0 (an empty message or stamp 0 among stamped states); ";
    return out.str();
  }

  std::string report() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream out;
    out << "sim states seen " << sim_states_ << " (non-finite " << sim_nonfinite_ << "), controller commands seen "
        << commands_ << ", answered malformed states of the allowed kinds:";
    for (const auto& [kind, count] : answered_)
      out << " " << (kind < kStateKindEnd ? kStateKindNames[kind] : "?") << " " << count << ";";
    return out.str();
  }

private:
  void problem(const std::string& text)
  {
    ++problem_count_;
    if (problems_.size() < 20)
      problems_.push_back(text);
  }

  mutable std::mutex mutex_;
  std::uint64_t sim_states_ = 0;
  std::uint64_t sim_nonfinite_ = 0;
  std::uint64_t latest_ = 0;
  std::uint64_t commands_ = 0;
  std::map<int, std::uint64_t> answered_;
  std::uint64_t answered_unstamped_ = 0;
  std::uint64_t stats_count_ = 0;
  std::uint32_t episode_ = 0;
  std::uint64_t total_steps_ = 0;
  std::vector<LogLine> logs_;
  std::uint64_t problem_count_ = 0;
  std::vector<std::string> problems_;
};

// What a node's subscription to a topic has received from this node over TCP, and how many of
// those it dropped from its full subscriber queue (never reaching its callback), as roscpp's
// getBusStats says. roscpp reports one connection per subscribed topic (the last one made,
// which is this node's: it connects after the nodes'); `known` is false when that is not ours.
struct Received
{
  bool known = false;
  std::uint64_t messages = 0;
  std::uint64_t drops = 0;
};

Received receivedFromThisNode(const std::string& node, const std::string& topic)
{
  Received received;
  XmlRpc::XmlRpcValue info = callNode(node, "getBusInfo");
  // roscpp answers getBusStats with [publish stats, subscribe stats, ...] in place of the usual
  // [code, message, value] (it fills the answer itself with the stats).
  XmlRpc::XmlRpcValue stats = callNodeRaw(node, "getBusStats");
  if (stats.getType() == XmlRpc::XmlRpcValue::TypeArray && stats.size() == 3 &&
      stats[0].getType() == XmlRpc::XmlRpcValue::TypeInt)
    stats = XmlRpc::XmlRpcValue(stats[2]);  // the usual form, should roscpp answer so
  if (info.getType() != XmlRpc::XmlRpcValue::TypeArray || stats.getType() != XmlRpc::XmlRpcValue::TypeArray ||
      stats.size() < 2 || stats[1].getType() != XmlRpc::XmlRpcValue::TypeArray)
    return received;
  const std::string self = ros::XMLRPCManager::instance()->getServerURI();
  int id = -1;
  for (int i = 0; i < info.size(); ++i)
  {
    XmlRpc::XmlRpcValue& c = info[i];
    if (c.getType() == XmlRpc::XmlRpcValue::TypeArray && c.size() >= 5 && static_cast<std::string>(c[2]) == "i" &&
        static_cast<std::string>(c[4]) == topic && static_cast<std::string>(c[1]) == self)
      id = static_cast<int>(c[0]);
  }
  for (int i = 0; i < stats[1].size(); ++i)
  {
    XmlRpc::XmlRpcValue& t = stats[1][i];
    if (t.getType() != XmlRpc::XmlRpcValue::TypeArray || t.size() < 2 || static_cast<std::string>(t[0]) != topic)
      continue;
    for (int j = 0; j < t[1].size(); ++j)
    {
      XmlRpc::XmlRpcValue& c = t[1][j];
      if (c.size() >= 4 && static_cast<int>(c[0]) == id)
      {
        received.known = true;
        received.messages = static_cast<std::uint64_t>(static_cast<int>(c[2]));
        received.drops = static_cast<std::uint64_t>(static_cast<int>(c[3]));
      }
    }
  }
  return received;
}

// What the controller's joint_states and the sim's joint_command and cart_effort subscriptions
// received from this node.
struct Delivery
{
  Received controller, command, effort;

  static Delivery now()
  {
    return {receivedFromThisNode(kControllerNode, kNs + "/joint_states"),
            receivedFromThisNode(kSimNode, kNs + "/joint_command"),
            receivedFromThisNode(kSimNode, kNs + "/cart_effort")};
  }
  // "N received, M of them dropped from the full subscriber queue", since `before`.
  static std::string since(const Received& before, const Received& after)
  {
    if (!before.known || !after.known)
      return "(not known)";
    return std::to_string(after.messages - before.messages) + " received, " +
           std::to_string(after.drops - before.drops) + " of them dropped from the full subscriber queue";
  }
  std::string since(const Delivery& before) const
  {
    return "controller's joint_states " + since(before.controller, controller) + "; sim's joint_command " +
           since(before.command, command) + "; sim's cart_effort " + since(before.effort, effort);
  }
};

const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");

std::string tableDir()
{
  return kTableDir.path();
}

// Saves the controller's table through its service and loads it back with the core's loader.
// Fails the test (and returns false) when either refuses or a value is not finite.
bool saveAndCheckTable(const std::string& name, cartpole_qlearning::QTable& table)
{
  cartpole_qlearning::SaveQTable srv;
  srv.request.path = name;
  const std::string service = kControllerNode + "/save_q_table";
  EXPECT_TRUE(ros::service::waitForService(service, ros::Duration(kWait))) << service << " is not there";
  if (!ros::service::call(service, srv))
  {
    ADD_FAILURE() << "the call to " << service << " failed";
    return false;
  }
  if (!srv.response.success)
  {
    ADD_FAILURE() << "save_q_table refused: " << srv.response.message;
    return false;
  }
  try
  {
    table = cartpole_qlearning::loadQTableFile(tableDir() + "/" + name);
  }
  catch (const cartpole_qlearning::FileError& e)
  {
    ADD_FAILURE() << "the saved table does not load back: " << e.what();
    return false;
  }
  const auto& values = table.values();
  const auto bad = std::find_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); });
  EXPECT_EQ(values.end(), bad) << "a non-finite value in the table at " << (bad - values.begin());
  EXPECT_FALSE(values.empty());
  return bad == values.end();
}

class BadMessagesTest : public ::testing::Test
{
protected:
  static void SetUpTestSuite()
  {
    ros::NodeHandle watch;
    watch.setCallbackQueue(&queue_);
    const ros::TransportHints no_delay = ros::TransportHints().tcpNoDelay();
    subs_.push_back(watch.subscribe(kNs + "/joint_states", 100000, &Observer::onState, &observer_, no_delay));
    subs_.push_back(watch.subscribe(kNs + "/joint_command", 100000, &Observer::onCommand, &observer_, no_delay));
    subs_.push_back(watch.subscribe(kNs + "/episode_stats", 10000, &Observer::onStats, &observer_));
    subs_.push_back(watch.subscribe("/rosout", 10000, &Observer::onLog, &observer_));
    spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
    spinner_->start();
  }

  static void TearDownTestSuite()
  {
    spinner_->stop();
    // Released while roscpp is up: destroyed among the statics at exit, the spinner's
    // NodeHandle unregisters through roscpp's already freed strings (ASan: heap-use-after-free).
    spinner_.reset();
    subs_.clear();
    states_pub_.shutdown();
    command_pub_.shutdown();
    effort_pub_.shutdown();
  }

  // Training runs, both nodes are connected to this one's publishers and the sim's time is far
  // enough along for the older stamps; records the nodes' pids and the table before.
  void SetUp() override
  {
    // The markers assume the shipped config: stamps multiples of 20 ms, efforts within 10 N.
    double tau = 0.0, force_mag = 0.0;
    ASSERT_TRUE(ros::param::get(kNs + "/physics/tau", tau) && ros::param::get(kNs + "/physics/force_mag", force_mag));
    ASSERT_EQ(kTick, static_cast<std::uint64_t>(std::llround(tau * 1e9)));
    ASSERT_EQ(kEffortLimit, force_mag);
    ASSERT_TRUE(spinUntil([] { return observer_.episode() >= 10 && observer_.latest() >= 60 * kSecond; }, kWait))
        << "training does not run: episode " << observer_.episode() << ", sim time " << observer_.latest() * 1e-9
        << " s";
    // Advertised once training runs, so that the nodes' connections to this node are their last
    // (see Received). No queue limit: a message published is a message written to the socket
    // (roscpp would drop the oldest of a full queue before writing it).
    if (!states_pub_)
    {
      ros::NodeHandle nh;
      states_pub_ = nh.advertise<sensor_msgs::JointState>(kNs + "/joint_states", 0);
      command_pub_ = nh.advertise<sensor_msgs::JointState>(kNs + "/joint_command", 0);
      effort_pub_ = nh.advertise<std_msgs::Float64>(kNs + "/cart_effort", 0);
    }
    ASSERT_TRUE(spinUntil(
        [] {
          // Each publisher also has this node's own subscriber (within the process).
          return states_pub_.getNumSubscribers() >= 2 && command_pub_.getNumSubscribers() >= 2 &&
                 effort_pub_.getNumSubscribers() >= 1;
        },
        kWait))
        << "a node did not connect to this one: subscribers " << states_pub_.getNumSubscribers() << ", "
        << command_pub_.getNumSubscribers() << ", " << effort_pub_.getNumSubscribers();
    if (base_ == 0)
      base_ = observer_.latest();
    sim_pid_ = pidOf(kSimNode);
    controller_pid_ = pidOf(kControllerNode);
    ASSERT_GT(sim_pid_, 0) << kSimNode << " does not answer getPid";
    ASSERT_GT(controller_pid_, 0) << kControllerNode << " does not answer getPid";
    ASSERT_TRUE(saveAndCheckTable("before.yaml", table_before_));
  }

  // A stamp newer than the latest state by less than a tick, marked with the kind.
  static std::uint64_t newer(int kind, std::uint64_t n, std::uint64_t latest)
  {
    return latest + 1000 * (n % 15000 + 1) + static_cast<std::uint64_t>(kind);
  }

  // A malformed state for the controller: the n-th of its kind.
  static sensor_msgs::JointStatePtr makeState(int kind, std::uint64_t n)
  {
    auto msg = boost::make_shared<sensor_msgs::JointState>();
    if (kind == kEmpty)
      return msg;
    const std::uint64_t latest = observer_.latest();
    const std::size_t slot = n % 2;  // which joint carries the bad value
    const double sign = n % 4 < 2 ? 1.0 : -1.0;
    std::uint64_t stamp = newer(kind, n, latest);
    msg->name = {"cart_joint", "pole_joint"};
    msg->position = {0.01, 0.02};  // a plausible state: near the middle, nearly upright
    msg->velocity = {0.0, -0.01};
    switch (kind)
    {
      case kUnknownNames:
        msg->name = slot == 0 ? std::vector<std::string>{"slider", "hinge"}
                              : std::vector<std::string>{"cart_joint_", "Pole_joint"};
        break;
      case kMissingJoint:
        msg->name = {slot == 0 ? "cart_joint" : "pole_joint"};
        msg->position.resize(1);
        msg->velocity.resize(1);
        break;
      case kNamesVsPositions:
        msg->position.resize(slot == 0 ? 1 : 3, 0.0);
        break;
      case kNamesVsVelocities:
        // (None at all is a position-only driver's valid state: its velocities are estimated.)
        msg->velocity.resize(slot == 0 ? 1 : 3, 0.0);
        break;
      case kNaNPosition:
        msg->position[slot] = kNaN;
        break;
      case kInfPosition:
        msg->position[slot] = sign * kInf;
        break;
      case kNaNVelocity:
        msg->velocity[slot] = kNaN;
        break;
      case kInfVelocity:
        msg->velocity[slot] = sign * kInf;
        break;
      case kOlderStamp:
        // Below every stamp kOlderStampTwice uses (one of which the controller may take as a
        // restarted sim's), each stamp used once: always older than the controller's last.
        stamp = base_ - 20 * kSecond - 1000 * n + kOlderStamp;
        break;
      case kZeroStamp:
        stamp = 0;
        break;
      case kRepeatedStamp:
        stamp = latest;
        break;
      case kOlderStampTwice:
        stamp = base_ - kSecond - 1000 * (n % 15000) + kOlderStampTwice;
        break;
      case kHugeValues:
        (n % 8 < 4 ? msg->position : msg->velocity)[slot] = sign * kHuge;
        break;
      default:
        break;
    }
    msg->header.stamp = timeOf(stamp);
    return msg;
  }

  // A malformed command for the sim (joint_command): the n-th of its kind.
  static sensor_msgs::JointStatePtr makeCommand(int kind, std::uint64_t n)
  {
    auto msg = boost::make_shared<sensor_msgs::JointState>();
    const std::uint64_t latest = observer_.latest();  // the pending state, or one older
    std::uint64_t stamp = latest;
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    msg->name = {"cart_joint"};
    msg->effort = {markerEffort(kind)};
    switch (kind)
    {
      case kWrongName:
        msg->name = {n % 2 == 0 ? "pole_joint" : "cart"};
        break;
      case kNoName:
        msg->name.clear();
        break;
      case kNoEffort:
        msg->effort.clear();
        break;
      case kNamesVsEfforts:
        if (n % 2 == 0)
          msg->name = {"cart_joint", "pole_joint"};
        else
          msg->effort.push_back(markerEffort(kind));
        break;
      case kNaNEffort:
        msg->effort = {kNaN};
        break;
      case kInfEffort:
        msg->effort = {sign * kInf};
        break;
      case kStaleStamp:
        stamp = latest - kTick * (2 + n % 50);
        break;
      case kFutureStamp:
        stamp = latest + 1000 * kSecond + 1000 * n;
        break;
      case kZeroStampCommand:
        stamp = 0;
        break;
      case kHugeEffort:
        msg->effort = {sign * kHuge};
        break;
      default:
        break;
    }
    msg->header.stamp = timeOf(stamp);
    return msg;
  }

  // Publishes the n-th message of a kind (kOlderStampTwice: a pair); returns how many.
  static int sendState(int kind, std::uint64_t n)
  {
    const sensor_msgs::JointStatePtr msg = makeState(kind, n);
    states_pub_.publish(msg);
    if (kind != kOlderStampTwice)
      return 1;
    states_pub_.publish(boost::make_shared<sensor_msgs::JointState>(*msg));
    return 2;
  }

  static int sendCommand(int kind, std::uint64_t n)
  {
    if (kind == kNaNCartEffort || kind == kInfCartEffort)
    {
      auto msg = boost::make_shared<std_msgs::Float64>();
      msg->data = kind == kNaNCartEffort ? kNaN : (n % 2 == 0 ? kInf : -kInf);
      effort_pub_.publish(msg);
      return 1;
    }
    command_pub_.publish(makeCommand(kind, n));
    return 1;
  }

  // A flood of one node: the kinds [first_kind, end_kind) in turn, published at `rate` a second
  // for kFloodSeconds, and how long the node's sockets took to receive them (`received` says
  // how many they have received so far).
  struct Flood
  {
    std::uint64_t sent = 0;
    double publish_seconds = 0.0;
    bool known = false;
    std::uint64_t received = 0;
    std::uint64_t dropped = 0;  // of those, dropped from the node's full subscriber queue
    double seconds = 0.0;       // from the first message published to the last received

    double receivedRate() const
    {
      return known && seconds > 0.0 ? received / seconds : std::nan("");
    }
    std::string report(double normal) const
    {
      std::ostringstream out;
      out << "published " << sent << " in " << publish_seconds << " s (" << sent / publish_seconds / normal
          << " x the normal rate); ";
      if (known)
        out << "received " << received << " in " << seconds << " s, " << receivedRate() << " a second ("
            << receivedRate() / normal << " x the normal rate), " << dropped
            << " of them dropped from the node's full subscriber queue";
      else
        out << "what the node received is not known";
      return out.str();
    }
  };

  static Flood flood(int first_kind, int end_kind, double rate, int (*send)(int, std::uint64_t),
                     const std::function<Received()>& received)
  {
    Flood result;
    const Received start = received();
    const ros::WallTime t0 = ros::WallTime::now();
    for (std::uint64_t i = 0; ros::ok();)
    {
      const double elapsed = (ros::WallTime::now() - t0).toSec();
      if (elapsed >= kFloodSeconds)
        break;
      for (; result.sent < rate * elapsed; ++i)
      {
        const int kind = first_kind + static_cast<int>(i % (end_kind - first_kind));
        const int n = send(kind, next_[kind]);
        next_[kind] += n;
        result.sent += n;
      }
      ros::WallDuration(0.0002).sleep();
    }
    result.publish_seconds = (ros::WallTime::now() - t0).toSec();
    // Until all arrived, or nothing more for 2 s.
    ros::WallTime last_progress = ros::WallTime::now();
    std::uint64_t last = 0;
    for (;;)
    {
      const Received now = received();
      if (!start.known || !now.known)
        break;
      const std::uint64_t got = now.messages - start.messages;
      if (got > last || result.seconds == 0.0)
      {
        last = got;
        last_progress = ros::WallTime::now();
        result.known = true;
        result.received = got;
        result.dropped = now.drops - start.drops;
        result.seconds = (last_progress - t0).toSec();
      }
      if (got >= result.sent || (ros::WallTime::now() - last_progress).toSec() > 2.0)
        break;
      ros::WallDuration(0.02).sleep();
    }
    return result;
  }

  // After the bad input: every check of the file comment. `window` is when the bad input began; `to_controller` and
  // `to_sim` count the bad messages sent to each.
  void expectHealthyAfter(const std::string& what, ros::WallTime window, const Delivery& before,
                          std::uint64_t to_controller, std::uint64_t to_sim)
  {
    const std::uint32_t episode = observer_.episode();
    const std::uint64_t steps = observer_.totalSteps();
    // Training goes on: new episodes, more steps.
    EXPECT_TRUE(
        spinUntil([&] { return observer_.episode() >= episode + 5 && observer_.totalSteps() >= steps + 500; }, kWait))
        << "training does not go on after " << what << ": episode " << episode << " -> " << observer_.episode()
        << ", total_steps " << steps << " -> " << observer_.totalSteps();

    // Both nodes are the processes they were.
    EXPECT_EQ(sim_pid_, pidOf(kSimNode)) << "the sim died or was replaced";
    EXPECT_EQ(controller_pid_, pidOf(kControllerNode)) << "the controller died or was replaced";

    // The table: finite, and trained further than before.
    cartpole_qlearning::QTable after;
    if (saveAndCheckTable("after_" + what + ".yaml", after))
    {
      EXPECT_GT(after.steps, table_before_.steps);
      EXPECT_GT(after.episodes, table_before_.episodes);
    }

    EXPECT_EQ("", observer_.violations());

    // Throttled warnings: each node has at most four kinds of warning about bad input, each at
    // most once a second (WallThrottle), plus a few said once (a silent sim, and the like). A
    // warning per message would be thousands.
    const double seconds = (ros::WallTime::now() - window).toSec();
    const std::size_t sim_warnings = observer_.warningsSince(kSimNode, window);
    const std::size_t controller_warnings = observer_.warningsSince(kControllerNode, window);
    const double bound = 4.0 * seconds + 10.0;
    EXPECT_LE(controller_warnings, bound)
        << "the controller warned " << controller_warnings << " times in " << seconds << " s for " << to_controller
        << " bad messages:" << observer_.warningKinds(kControllerNode, window);
    EXPECT_LE(sim_warnings, bound) << "the sim warned " << sim_warnings << " times in " << seconds << " s for "
                                   << to_sim << " bad messages:" << observer_.warningKinds(kSimNode, window);
    EXPECT_LE(controller_warnings, to_controller / 100);
    EXPECT_LE(sim_warnings, to_sim / 100);

    std::ostringstream out;
    out << what << ": " << to_controller << " bad messages to the controller, " << to_sim
        << " to the sim; then training went on from episode " << episode << " to " << observer_.episode()
        << "; warnings in the " << seconds << " s since the bad input began: controller " << controller_warnings
        << ", sim " << sim_warnings << "; what reached the nodes: " << Delivery::now().since(before) << "; "
        << observer_.report();
    std::cout << "[bad_messages] " << out.str() << std::endl;
    RecordProperty("summary", out.str());
  }

  static ros::CallbackQueue queue_;
  static std::unique_ptr<ros::AsyncSpinner> spinner_;
  static std::vector<ros::Subscriber> subs_;
  static Observer observer_;
  static ros::Publisher states_pub_;
  static ros::Publisher command_pub_;
  static ros::Publisher effort_pub_;
  static std::uint64_t base_;                 // the sim time the older stamps are counted back from
  static std::map<int, std::uint64_t> next_;  // the next n of each kind: stamps are never reused

  int sim_pid_ = -1;
  int controller_pid_ = -1;
  cartpole_qlearning::QTable table_before_;
};
ros::CallbackQueue BadMessagesTest::queue_;
std::unique_ptr<ros::AsyncSpinner> BadMessagesTest::spinner_;
std::vector<ros::Subscriber> BadMessagesTest::subs_;
Observer BadMessagesTest::observer_;
ros::Publisher BadMessagesTest::states_pub_;
ros::Publisher BadMessagesTest::command_pub_;
ros::Publisher BadMessagesTest::effort_pub_;
std::uint64_t BadMessagesTest::base_ = 0;
std::map<int, std::uint64_t> BadMessagesTest::next_;

TEST_F(BadMessagesTest, ThousandOfEachMalformedKindWhileTraining)
{
  // One message of every kind in turn to each node (kOlderStampTwice: a pair every other
  // round), a short pause after each pair of messages: the nodes take them in as they come, so
  // that (nearly) every one reaches its callback rather than a full subscriber queue.
  const Delivery before = Delivery::now();
  const ros::WallTime window = ros::WallTime::now();
  std::map<int, int> sent;
  std::uint64_t to_controller = 0, to_sim = 0;
  for (int round = 0; round < kPerKind && ros::ok(); ++round)
  {
    std::vector<int> states;
    for (int kind = kUnknownNames; kind < kStateKindEnd; ++kind)
    {
      if (kind != kOlderStampTwice || round % 2 == 0)
        states.push_back(kind);
    }
    const int commands = kCommandKindEnd - kWrongName;
    for (std::size_t i = 0; i < std::max<std::size_t>(states.size(), commands); ++i)
    {
      if (i < states.size())
      {
        const int kind = states[i];
        const int n = sendState(kind, next_[kind]++);
        next_[kind] += n - 1;
        sent[kind] += n;
        to_controller += n;
      }
      if (i < static_cast<std::size_t>(commands))
      {
        const int kind = kWrongName + static_cast<int>(i);
        sendCommand(kind, next_[kind]++);
        ++sent[kind];
        ++to_sim;
      }
      ros::WallDuration(0.0001).sleep();
    }
  }
  const double seconds = (ros::WallTime::now() - window).toSec();
  std::ostringstream counts;
  for (const auto& [kind, count] : sent)
  {
    counts << (kind < kStateKindEnd ? kStateKindNames[kind] : kCommandKindNames[kind - kWrongName]) << " " << count
           << "; ";
    EXPECT_GE(count, kPerKind);
  }
  std::cout << "[bad_messages] sent in " << seconds << " s: " << counts.str() << std::endl;
  expectHealthyAfter("each_kind", window, before, to_controller, to_sim);
}

TEST_F(BadMessagesTest, FloodAtTenTimesTheStepRate)
{
  // The normal rate: steps (episode_stats' total_steps) and states (the sim's joint_states) a
  // second over a few seconds of undisturbed training.
  const ros::WallTime from = ros::WallTime::now();
  const std::uint64_t steps_from = observer_.totalSteps();
  const std::uint64_t states_from = observer_.simStates();
  spinUntil([] { return false; }, 3.0);
  const double measured = (ros::WallTime::now() - from).toSec();
  const double step_rate = (observer_.totalSteps() - steps_from) / measured;
  const double state_rate = (observer_.simStates() - states_from) / measured;
  const double normal = std::max(step_rate, state_rate);
  ASSERT_GT(normal, 0.0) << "training does not run";

  // Each node in turn: every kind in turn at kFloodFactor times the normal rate for
  // kFloodSeconds, then the time until the node's sockets have received them all. The rate
  // reported is what the node received over that time.
  const Delivery before = Delivery::now();
  const ros::WallTime window = ros::WallTime::now();
  const double target = kFloodFactor * normal;
  const Flood to_controller = flood(kUnknownNames, kStateKindEnd, target, &sendState,
                                    [] { return receivedFromThisNode(kControllerNode, kNs + "/joint_states"); });
  const Flood to_sim = flood(kWrongName, kCommandKindEnd, target, &sendCommand, [] {
    const Received command = receivedFromThisNode(kSimNode, kNs + "/joint_command");
    const Received effort = receivedFromThisNode(kSimNode, kNs + "/cart_effort");
    return Received{command.known && effort.known, command.messages + effort.messages, command.drops + effort.drops};
  });
  std::ostringstream out;
  out << "normal rate " << step_rate << " steps/s, " << state_rate << " states/s; flood at " << target
      << " messages/s (" << kFloodFactor << " x) for " << kFloodSeconds << " s: controller "
      << to_controller.report(normal) << "; sim " << to_sim.report(normal);
  std::cout << "[bad_messages] " << out.str() << std::endl;
  RecordProperty("flood", out.str());
  // Not a test of this machine's speed: the ratio is reported, not asserted.
  if (!(std::min(to_controller.receivedRate(), to_sim.receivedRate()) >= 10.0 * normal))
    std::cout << "[bad_messages] NOTE: a node received less than 10 x the normal rate on this machine" << std::endl;

  expectHealthyAfter("flood", window, before, to_controller.sent, to_sim.sent);
}
}  // namespace
