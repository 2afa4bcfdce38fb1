// A user resets the sim again and again while the controller trains in lockstep, so that
// answers are in flight when the start state changes under them. From the recorded states and
// commands, every step the sim took is recomputed with the core's dynamics: each new state must
// be the physics of the state its command was stamped with, under that command's effort. (With
// commands that carry no stamp, the sim paired them with states by arrival, and after a reset
// most steps were driven by a command chosen for another state.)
#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "ros_test_support.h"
#include "rostest_main.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <vector>

using cartpole_qlearning::CartPoleDynamics;
using cartpole_qlearning::CartPoleParams;
using cartpole_qlearning::CartPoleState;
using cartpole_qlearning::test::spinUntil;

namespace
{
// The controller's table folder, which the .test file gives this node too.
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");
constexpr std::uint64_t kTauNs = 20000000;  // config/cartpole.yaml: tau 0.02 s
constexpr double kTolerance = 1e-9;

struct Recorded
{
  CartPoleState state;
  double cart_effort = 0.0;  // the force the sim applied in the step that led here (0 after a reset)
};

bool read(const sensor_msgs::JointState& msg, Recorded& out)
{
  const auto index = [&](const char* name) {
    return static_cast<std::size_t>(std::find(msg.name.begin(), msg.name.end(), name) - msg.name.begin());
  };
  const std::size_t cart = index("cart_joint");
  const std::size_t pole = index("pole_joint");
  if (cart >= msg.name.size() || pole >= msg.name.size() || msg.position.size() != msg.name.size() ||
      msg.velocity.size() != msg.name.size() || msg.effort.size() != msg.name.size())
    return false;
  out.state = CartPoleState(msg.position[cart], msg.velocity[cart], msg.position[pole], msg.velocity[pole]);
  out.cart_effort = msg.effort[cart];
  return true;
}
}  // namespace

TEST(UserReset, EveryStepIsThePhysicsOfTheStateItsCommandWasStampedWith)
{
  ros::NodeHandle nh;
  std::map<std::uint64_t, Recorded> states;               // by stamp; a repeat carries the same values
  std::map<std::uint64_t, std::vector<double>> commands;  // efforts by the stamp they answer
  std::size_t bad_messages = 0;
  std::size_t repeats_differing = 0;
  ros::Subscriber state_sub = nh.subscribe<sensor_msgs::JointState>(
      "/user_reset/joint_states", 100000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        Recorded r;
        if (!read(*m, r))
        {
          ++bad_messages;
          return;
        }
        const auto [it, inserted] = states.emplace(m->header.stamp.toNSec(), r);
        if (!inserted && (it->second.state != r.state || it->second.cart_effort != r.cart_effort))
          ++repeats_differing;
      }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::Subscriber command_sub = nh.subscribe<sensor_msgs::JointState>(
      "/user_reset/joint_command", 100000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        if (m->name.size() != 1 || m->name[0] != "cart_joint" || m->effort.size() != 1)
        {
          ++bad_messages;
          return;
        }
        // An unstamped zero is the controller stopping the cart at an episode's end; it answers
        // no state (the sim steps on none), and kept here at stamp 0 it would hide that the
        // recording of commands began after that of states.
        if (m->header.stamp.isZero())
        {
          if (m->effort[0] != 0.0)
            ++bad_messages;
          return;
        }
        commands[m->header.stamp.toNSec()].push_back(m->effort[0]);
      }),
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ASSERT_TRUE(ros::service::waitForService("/user_reset/cartpole_sim/reset", ros::Duration(30.0)));
  ros::ServiceClient reset = nh.serviceClient<cartpole_qlearning::Reset>("/user_reset/cartpole_sim/reset");
  ASSERT_TRUE(spinUntil([&] { return states.size() > 2000; }, 30.0)) << "training does not run: " << states.size();

  // 30 resets at random moments, a few milliseconds to a tenth of a second apart: most land
  // between a state and its answer.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> pause(0.002, 0.1);
  int user_resets = 0;
  for (int i = 0; i < 30; ++i)
  {
    spinUntil([] { return false; }, pause(random));
    cartpole_qlearning::Reset call;
    if (i % 3 == 0)
      call.request.state = {0.0, 0.0, 0.01 * (i % 5), 0.0};
    ASSERT_TRUE(reset.call(call)) << "the reset call failed";
    ASSERT_TRUE(call.response.success) << call.response.message;
    ++user_resets;
  }
  const std::size_t after_resets = states.size();
  ASSERT_TRUE(spinUntil([&] { return states.size() > after_resets + 2000; }, 30.0))
      << "training did not go on after the resets";
  state_sub.shutdown();
  // The answer to the last state but one, which the last state's check needs, comes on another
  // connection and may not be here yet: the commands are recorded on until one answers the newest
  // state or a later one (a connection delivers in order, so every earlier answer is here then).
  const std::uint64_t newest = states.rbegin()->first;
  EXPECT_TRUE(spinUntil([&] { return !commands.empty() && commands.rbegin()->first >= newest; }, 10.0))
      << "no command answered the last state recorded, or a later one";
  command_sub.shutdown();

  EXPECT_EQ(0u, bad_messages);
  EXPECT_EQ(0u, repeats_differing) << "a repeated stamp carried other values";
  const CartPoleDynamics dynamics{CartPoleParams()};
  std::size_t checked = 0;
  std::size_t resets_seen = 0;
  std::size_t wrong = 0;
  std::ostringstream first_wrong;
  ASSERT_FALSE(commands.empty());
  const std::uint64_t first_command = commands.begin()->first;
  for (const auto& [stamp, recorded] : states)
  {
    if (recorded.cart_effort == 0.0)
    {
      ++resets_seen;  // a start state: the actions are +-10 N, so only a reset applies none
      continue;
    }
    const auto previous = states.find(stamp - kTauNs);
    const auto answer = commands.find(stamp - kTauNs);
    if (previous == states.end() || stamp - kTauNs < first_command)
      continue;  // the recording of states or of commands began after that step
    ++checked;
    if (answer == commands.end())
    {
      if (wrong++ == 0)
        first_wrong << "the state at " << stamp << " ns follows a state no command answered";
      continue;
    }
    const double effort = answer->second.front();
    const CartPoleState expected = dynamics.step(previous->second.state, effort);
    const bool exact = ((expected - recorded.state).array().abs() <= kTolerance).all() &&
                       recorded.cart_effort == effort &&
                       std::all_of(answer->second.begin(), answer->second.end(), [&](double e) { return e == effort; });
    if (!exact && wrong++ == 0)
      first_wrong << "the state at " << stamp << " ns is [" << recorded.state.transpose() << "] under "
                  << recorded.cart_effort << " N; the physics of the state before it under its command (" << effort
                  << " N) give [" << expected.transpose() << "]";
  }
  EXPECT_GT(checked, 4000u) << "too few steps recorded to judge";
  EXPECT_GE(resets_seen, static_cast<std::size_t>(user_resets)) << "the user's resets did not all show";
  EXPECT_EQ(0u, wrong) << wrong << " of " << checked
                       << " steps do not follow from their command: " << first_wrong.str();
}
