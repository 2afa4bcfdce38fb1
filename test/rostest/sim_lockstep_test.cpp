// cartpole_sim in lockstep mode, started by sim_lockstep.test: one command answers one state,
// the answer is the core's exact next state, stamps advance by tau, /clock follows them, and
// time never goes back, resets included.
#include "cartpole_qlearning/Reset.h"
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include "ros_test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace
{
using cartpole_qlearning::CartPoleDynamics;
using cartpole_qlearning::CartPoleParams;
using cartpole_qlearning::CartPoleState;

constexpr double kTau = 0.02;          // config/cartpole.yaml
constexpr double kEffortLimit = 10.0;  // config/sim.yaml
constexpr double kTolerance = 1e-9;
constexpr double kWaitSeconds = 15.0;  // generous: the CI machine is loaded
constexpr double kQuietSeconds = 0.25;

// A joint_states message read by joint name, as the controller reads it.
struct Observed
{
  ros::Time stamp;
  CartPoleState state = CartPoleState::Constant(std::numeric_limits<double>::quiet_NaN());
  double cart_effort = std::numeric_limits<double>::quiet_NaN();
  double pole_effort = std::numeric_limits<double>::quiet_NaN();
};

::testing::AssertionResult readJointState(const sensor_msgs::JointState& msg, Observed& out)
{
  const auto index = [&](const char* name) {
    const auto it = std::find(msg.name.begin(), msg.name.end(), name);
    return it == msg.name.end() ? -1 : static_cast<int>(it - msg.name.begin());
  };
  const int cart = index("cart_joint");
  const int pole = index("pole_joint");
  if (cart < 0 || pole < 0)
    return ::testing::AssertionFailure() << "joint_states without cart_joint or pole_joint";
  const std::size_t n = msg.name.size();
  if (msg.position.size() != n || msg.velocity.size() != n || msg.effort.size() != n)
    return ::testing::AssertionFailure() << "joint_states with " << n << " names, " << msg.position.size()
                                         << " positions, " << msg.velocity.size() << " velocities, "
                                         << msg.effort.size() << " efforts";
  out.stamp = msg.header.stamp;
  out.state = CartPoleState(msg.position[cart], msg.velocity[cart], msg.position[pole], msg.velocity[pole]);
  out.cart_effort = msg.effort[cart];
  out.pole_effort = msg.effort[pole];
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult near(const CartPoleState& expected, const CartPoleState& actual, double tolerance)
{
  if (((expected - actual).array().abs() <= tolerance).all())
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "expected [" << expected.transpose() << "], got [" << actual.transpose()
                                       << "], difference [" << (actual - expected).transpose() << "]";
}

class SimLockstepTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    states_sub_ = nh_.subscribe("/cartpole/joint_states", 100, &SimLockstepTest::onJointState, this,
                                ros::TransportHints().tcpNoDelay());
    clock_sub_ = nh_.subscribe("/clock", 100, &SimLockstepTest::onClock, this, ros::TransportHints().tcpNoDelay());
    effort_pub_ = nh_.advertise<std_msgs::Float64>("/cartpole/cart_effort", 10);
    command_pub_ = nh_.advertise<sensor_msgs::JointState>("/cartpole/joint_command", 10);
    reset_client_ = nh_.serviceClient<cartpole_qlearning::Reset>("/cartpole/cartpole_sim/reset");
    ASSERT_TRUE(ros::service::waitForService(reset_client_.getService(), ros::Duration(20.0)))
        << reset_client_.getService() << " never came up";
    // Publisher side: the sim's subscription is connected, so a command is delivered.
    ASSERT_TRUE(spinUntil([&] {
      return effort_pub_.getNumSubscribers() > 0 && command_pub_.getNumSubscribers() > 0 &&
             states_sub_.getNumPublishers() > 0 && clock_sub_.getNumPublishers() > 0;
    })) << "the sim never connected to cart_effort, joint_command, joint_states or /clock";
  }

  void onJointState(const sensor_msgs::JointStateConstPtr& msg)
  {
    states_.push_back(*msg);
  }

  void onClock(const rosgraph_msgs::ClockConstPtr& msg)
  {
    clocks_.push_back(msg->clock);
  }

  bool spinUntil(const std::function<bool()>& done, double seconds = kWaitSeconds)
  {
    return cartpole_qlearning::test::spinUntil(done, seconds);
  }

  void spinFor(double seconds)
  {
    spinUntil([] { return false; }, seconds);
  }

  cartpole_qlearning::Reset::Response callReset(const std::vector<double>& state)
  {
    cartpole_qlearning::Reset reset;
    reset.request.state = state;
    EXPECT_TRUE(reset_client_.call(reset)) << "the reset call itself failed";
    return reset.response;
  }

  static bool sameState(const sensor_msgs::JointState& a, const sensor_msgs::JointState& b)
  {
    return a.header.stamp == b.header.stamp && a.name == b.name && a.position == b.position &&
           a.velocity == b.velocity && a.effort == b.effort;
  }

  bool newStateArrived(std::size_t from) const
  {
    for (std::size_t i = from; i < states_.size(); ++i)
    {
      if (!have_current_ || states_[i].header.stamp > current_.header.stamp)
        return true;
    }
    return false;
  }

  // Checks what arrived since `from` and makes the one new state current. The sim may publish
  // the current state again (same stamp, same values: for a new subscriber, or after
  // lockstep_timeout), but exactly one new state may follow, later than the current one.
  // copies: the new state may itself come more than once (around a reset, a new subscriber's
  // repeat can follow it).
  ::testing::AssertionResult takeOneNewState(std::size_t from, bool copies)
  {
    const sensor_msgs::JointState* newest = nullptr;
    for (std::size_t i = from; i < states_.size(); ++i)
    {
      if (newest == nullptr || states_[i].header.stamp > newest->header.stamp)
        newest = &states_[i];
    }
    if (newest == nullptr || (have_current_ && newest->header.stamp <= current_.header.stamp))
      return ::testing::AssertionFailure() << "no new state";
    int count = 0;
    for (std::size_t i = from; i < states_.size(); ++i)
    {
      const sensor_msgs::JointState& msg = states_[i];
      if (msg.header.stamp == newest->header.stamp)
      {
        if (!sameState(msg, *newest))
          return ::testing::AssertionFailure() << "two different states with the stamp " << msg.header.stamp;
        ++count;
      }
      else if (count > 0)
      {
        return ::testing::AssertionFailure() << "an older state (stamp " << msg.header.stamp
                                             << ") came after the new one (" << newest->header.stamp << ")";
      }
      else if (have_current_ && !sameState(msg, current_))
      {
        return ::testing::AssertionFailure()
               << "a state at " << msg.header.stamp << " besides the new one at " << newest->header.stamp
               << " (a repeat must be the current state, at " << current_.header.stamp << ")";
      }
    }
    if (!copies && count != 1)
      return ::testing::AssertionFailure() << "the new state came " << count << " times";
    current_ = *newest;
    have_current_ = true;
    return ::testing::AssertionSuccess();
  }

  // Nothing but repeats of the current state arrived since `from`.
  ::testing::AssertionResult noNewState(std::size_t from) const
  {
    for (std::size_t i = from; i < states_.size(); ++i)
    {
      if (!have_current_ || !sameState(states_[i], current_))
        return ::testing::AssertionFailure() << "a new state at " << states_[i].header.stamp;
    }
    return ::testing::AssertionSuccess();
  }

  Observed current() const
  {
    Observed observed;
    EXPECT_TRUE(have_current_);
    if (have_current_)
    {
      EXPECT_TRUE(readJointState(current_, observed));
    }
    return observed;
  }

  // Resets to the state and returns the joint_states that carries it. The sim publishes it
  // once; if joint_states was not quite connected yet it is lost, so the reset is repeated.
  Observed resetTo(const CartPoleState& start)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kWaitSeconds);
    while (ros::ok() && ros::WallTime::now() < deadline)
    {
      const std::size_t before = states_.size();
      const auto response = callReset({start[0], start[1], start[2], start[3]});
      EXPECT_TRUE(response.success) << response.message;
      const bool arrived = spinUntil(
          [&] {
            Observed observed;
            return newStateArrived(before) && readJointState(states_.back(), observed) &&
                   near(start, observed.state, 0.0);
          },
          3.0);
      if (arrived)
      {
        spinFor(kQuietSeconds);
        EXPECT_TRUE(takeOneNewState(before, true)) << "after a reset";
        const Observed observed = current();
        EXPECT_TRUE(near(start, observed.state, 0.0));
        return observed;
      }
    }
    ADD_FAILURE() << "no joint_states carrying the reset state [" << start.transpose() << "]";
    return Observed();
  }

  // A joint_command as the controller sends it: the effort of cart_joint, stamped with the stamp
  // of the state it answers.
  void command(double effort, const ros::Time& answers)
  {
    sensor_msgs::JointState msg;
    msg.header.stamp = answers;
    msg.name = {"cart_joint"};
    msg.effort = {effort};
    command_pub_.publish(msg);
  }

  // Sends one command and returns the one state that answers it; quiet: also waits a while to
  // see that no second state follows.
  Observed step(double effort, bool quiet)
  {
    const std::size_t before = states_.size();
    std_msgs::Float64 msg;
    msg.data = effort;
    effort_pub_.publish(msg);
    EXPECT_TRUE(spinUntil([&] { return newStateArrived(before); }))
        << "no joint_states answered the command " << effort;
    if (quiet)
      spinFor(kQuietSeconds);
    EXPECT_TRUE(takeOneNewState(before, false)) << "one command must answer with exactly one state";
    return current();
  }

  // The /clock that goes with a stamp arrives (it is published just before the joint state,
  // on another connection).
  void expectClock(const ros::Time& stamp)
  {
    const bool arrived = spinUntil([&] { return std::find(clocks_.begin(), clocks_.end(), stamp) != clocks_.end(); },
                                   clock_missing_ ? 0.0 : kWaitSeconds);
    clock_missing_ = !arrived;
    ASSERT_TRUE(arrived) << "no /clock at the joint_states stamp " << stamp;
    EXPECT_TRUE(std::is_sorted(clocks_.begin(), clocks_.end())) << "/clock went backwards";
    EXPECT_EQ(stamp, clocks_.back()) << "/clock is not at the newest joint_states stamp";
  }

  // Steps through the forces from a known state, checking every answer against the core.
  void expectExactSteps(const Observed& start, const std::vector<double>& forces)
  {
    const CartPoleDynamics dynamics{CartPoleParams()};
    CartPoleState expected = start.state;
    ros::Time stamp = start.stamp;
    for (std::size_t i = 0; i < forces.size(); ++i)
    {
      SCOPED_TRACE("step " + std::to_string(i) + ", force " + std::to_string(forces[i]));
      const Observed observed = step(forces[i], i < 3 || i % 5 == 0);
      const double applied = std::clamp(forces[i], -kEffortLimit, kEffortLimit);
      expected = dynamics.step(expected, applied);
      EXPECT_TRUE(near(expected, observed.state, kTolerance));
      EXPECT_EQ(applied, observed.cart_effort);
      EXPECT_EQ(0.0, observed.pole_effort);
      EXPECT_NEAR(kTau, (observed.stamp - stamp).toSec(), 1e-9);
      expectClock(observed.stamp);
      stamp = observed.stamp;
      if (::testing::Test::HasFailure())
        return;  // the rest would only repeat the first difference
    }
  }

  ros::NodeHandle nh_;
  ros::Subscriber states_sub_;
  ros::Subscriber clock_sub_;
  ros::Publisher effort_pub_;
  ros::Publisher command_pub_;
  ros::ServiceClient reset_client_;
  std::vector<sensor_msgs::JointState> states_;
  std::vector<ros::Time> clocks_;
  sensor_msgs::JointState current_;  // the newest state, which the next command answers
  bool have_current_ = false;
  bool clock_missing_ = false;  // once /clock failed to come, the test does not wait for it again
};

TEST_F(SimLockstepTest, EachCommandStepsOnceToTheCoresNextState)
{
  const Observed start = resetTo(CartPoleState(0.01, -0.02, 0.03, -0.04));
  ASSERT_FALSE(HasFailure());
  EXPECT_EQ(0.0, start.cart_effort) << "no force acts on a state just reset";
  expectClock(start.stamp);

  std::vector<double> forces;
  for (int i = 0; i < 30; ++i)
    forces.push_back((i % 3 == 0 || i % 7 == 0) ? 10.0 : -10.0);
  expectExactSteps(start, forces);
}

TEST_F(SimLockstepTest, OutOfRangeCommandsAreClampedAndNonFiniteOnesStepNothing)
{
  const Observed start = resetTo(CartPoleState(-0.03, 0.02, -0.01, 0.05));
  ASSERT_FALSE(HasFailure());
  expectExactSteps(start, {25.0, -1e6, 3.5});
  ASSERT_FALSE(HasFailure());

  const Observed before = current();
  const std::size_t count = states_.size();
  for (const double bad :
       {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()})
  {
    std_msgs::Float64 msg;
    msg.data = bad;
    effort_pub_.publish(msg);
  }
  spinFor(0.5);
  EXPECT_TRUE(noNewState(count)) << "a non-finite command must not step the sim";
  // The pending state still waits for its answer, and gets it.
  expectExactSteps(before, {-10.0, 10.0});
}

TEST_F(SimLockstepTest, TimeNeverGoesBackAcrossResets)
{
  const Observed first = resetTo(CartPoleState(0.0, 0.1, 0.02, 0.0));
  ASSERT_FALSE(HasFailure());
  expectExactSteps(first, {10.0, 10.0, -10.0});
  ASSERT_FALSE(HasFailure());
  const ros::Time before_reset = current().stamp;

  const Observed again = resetTo(CartPoleState(0.01, -0.02, 0.03, -0.04));
  ASSERT_FALSE(HasFailure());
  EXPECT_GT(again.stamp, before_reset) << "time went back (or stood still) across a reset";
  expectClock(again.stamp);

  // A random start: within +-start_state_bound (0.05), later again, and stepped exactly.
  const std::size_t count = states_.size();
  const auto response = callReset({});
  EXPECT_TRUE(response.success) << response.message;
  ASSERT_TRUE(spinUntil([&] { return newStateArrived(count); })) << "no joint_states after a random reset";
  spinFor(kQuietSeconds);
  ASSERT_TRUE(takeOneNewState(count, true)) << "after a random reset";
  const Observed random = current();
  EXPECT_TRUE((random.state.array().abs() <= 0.05).all()) << random.state.transpose();
  EXPECT_GT(random.stamp, again.stamp);
  expectClock(random.stamp);
  expectExactSteps(random, {-10.0, 10.0});
}

TEST_F(SimLockstepTest, RefusedResetChangesNeitherStateNorTime)
{
  const Observed start = resetTo(CartPoleState(0.02, 0.0, -0.03, 0.01));
  ASSERT_FALSE(HasFailure());
  expectExactSteps(start, {10.0});
  ASSERT_FALSE(HasFailure());
  const Observed before = current();
  const std::size_t count = states_.size();
  for (const std::vector<double>& bad :
       {std::vector<double>{0.0, 0.0, 0.0}, std::vector<double>{0.0, std::nan(""), 0.0, 0.0},
        std::vector<double>{0.0, 0.0, 0.0, 0.0, 0.0}})
  {
    const auto response = callReset(bad);
    EXPECT_FALSE(response.success) << "a reset with " << bad.size() << " values was accepted";
    EXPECT_FALSE(response.message.empty());
  }
  spinFor(0.5);
  EXPECT_TRUE(noNewState(count)) << "a refused reset published a state";
  expectExactSteps(before, {-10.0, -10.0});
}

TEST_F(SimLockstepTest, OnlyTheCommandStampedWithThePendingStateStepsIt)
{
  const Observed start = resetTo(CartPoleState(0.02, -0.01, 0.01, 0.03));
  ASSERT_FALSE(HasFailure());
  expectExactSteps(start, {10.0});  // a state before the pending one, for a stale stamp
  ASSERT_FALSE(HasFailure());
  const Observed pending = current();
  const ros::Duration tau(kTau);

  // Stray commands: an answer to the state before, one to a state not yet published, one
  // without a stamp, one for another joint, one with mismatched arrays. None may step the sim.
  const std::size_t count = states_.size();
  command(-10.0, pending.stamp - tau);
  command(-10.0, pending.stamp + tau);
  command(-10.0, ros::Time(0));
  sensor_msgs::JointState other;
  other.header.stamp = pending.stamp;
  other.name = {"pole_joint"};
  other.effort = {-10.0};
  command_pub_.publish(other);
  sensor_msgs::JointState mismatched;
  mismatched.header.stamp = pending.stamp;
  mismatched.name = {"cart_joint", "pole_joint"};
  mismatched.effort = {-10.0};
  command_pub_.publish(mismatched);
  spinFor(0.5);
  EXPECT_TRUE(noNewState(count)) << "a command with a wrong stamp or shape stepped the sim";

  // The pending state's own answer steps it, once, to the core's next state; the same answer
  // again (a duplicate) and a late one for the state it replaced step nothing.
  const std::size_t before = states_.size();
  command(10.0, pending.stamp);
  ASSERT_TRUE(spinUntil([&] { return newStateArrived(before); })) << "the stamped answer did not step the sim";
  command(10.0, pending.stamp);
  command(-10.0, pending.stamp - tau);
  spinFor(0.5);
  ASSERT_TRUE(takeOneNewState(before, false)) << "one stamped answer must step exactly once";
  const Observed next = current();
  EXPECT_TRUE(near(CartPoleDynamics(CartPoleParams()).step(pending.state, 10.0), next.state, kTolerance));
  EXPECT_EQ(10.0, next.cart_effort);
  EXPECT_NEAR(kTau, (next.stamp - pending.stamp).toSec(), 1e-9);
  expectClock(next.stamp);
}

TEST_F(SimLockstepTest, AnAnswerInFlightDuringAResetIsDropped)
{
  const Observed start = resetTo(CartPoleState(0.01, 0.0, -0.02, 0.0));
  ASSERT_FALSE(HasFailure());
  // A user's reset comes between the state and its answer: the answer, stamped with the state
  // the reset replaced, must not step the new start state.
  const Observed restart = resetTo(CartPoleState(-0.01, 0.02, 0.0, 0.01));
  ASSERT_FALSE(HasFailure());
  const std::size_t count = states_.size();
  command(10.0, start.stamp);
  spinFor(0.5);
  EXPECT_TRUE(noNewState(count)) << "an answer to the state before the reset stepped the new one";
  const std::size_t before = states_.size();
  command(-10.0, restart.stamp);
  ASSERT_TRUE(spinUntil([&] { return newStateArrived(before); }));
  ASSERT_TRUE(takeOneNewState(before, false));
  EXPECT_TRUE(near(CartPoleDynamics(CartPoleParams()).step(restart.state, -10.0), current().state, kTolerance));
}

// Started by sim_lockstep_repeat.test, with a short ~lockstep_timeout (0.2 s): a state nobody
// answers is published again with the same stamp and the same values, /clock stays, and one
// answer then steps exactly once.
using SimLockstepRepeatTest = SimLockstepTest;

TEST_F(SimLockstepRepeatTest, AnUnansweredStateIsPublishedAgainUnchangedAndOneAnswerStepsOnce)
{
  const CartPoleState start(0.01, -0.02, 0.03, -0.04);
  const std::size_t before_reset = states_.size();
  const auto response = callReset({start[0], start[1], start[2], start[3]});
  ASSERT_TRUE(response.success) << response.message;
  // Its first publication may be lost to a fresh connection; the repeats are not.
  std::size_t first = before_reset;
  const auto carries = [&](std::size_t i, const CartPoleState& state) {
    Observed observed;
    return readJointState(states_[i], observed) && near(state, observed.state, 0.0);
  };
  ASSERT_TRUE(spinUntil([&] {
    for (; first < states_.size(); ++first)
    {
      if (carries(first, start))
        return true;
    }
    return false;
  })) << "no joint_states carried the reset state";
  ASSERT_TRUE(spinUntil([&] { return states_.size() >= first + 3; })) << "an unanswered state was not published again";

  // A repeat every lockstep_timeout or so, not a flood, and they go on.
  const std::size_t window_start = states_.size();
  spinFor(1.0);
  EXPECT_LE(states_.size() - window_start, 8u) << "repeats come far more often than every lockstep_timeout (0.2 s)";
  const std::size_t window_end = states_.size();
  EXPECT_TRUE(spinUntil([&] { return states_.size() > window_end; })) << "the repeats stopped";

  const ros::Time stamp = states_[first].header.stamp;
  for (std::size_t i = first; i < states_.size(); ++i)
  {
    EXPECT_EQ(stamp, states_[i].header.stamp) << "repeat " << i - first;
    EXPECT_EQ(states_[first].position, states_[i].position) << "repeat " << i - first;
    EXPECT_EQ(states_[first].velocity, states_[i].velocity) << "repeat " << i - first;
    EXPECT_EQ(states_[first].effort, states_[i].effort) << "repeat " << i - first;
  }
  expectClock(stamp);

  // One answer, while the repeats go on: one step, to the core's next state.
  const std::size_t answered_at = states_.size();
  std_msgs::Float64 msg;
  msg.data = 10.0;
  effort_pub_.publish(msg);
  std::size_t next = answered_at;
  const auto stepped = [&] {
    for (; next < states_.size(); ++next)
    {
      if (states_[next].header.stamp != stamp)
        return true;
    }
    return false;
  };
  ASSERT_TRUE(spinUntil(stepped)) << "the answer did not step the sim";
  const CartPoleState expected = CartPoleDynamics(CartPoleParams()).step(start, 10.0);
  Observed observed;
  ASSERT_TRUE(readJointState(states_[next], observed));
  EXPECT_TRUE(near(expected, observed.state, kTolerance));
  EXPECT_EQ(10.0, observed.cart_effort);
  EXPECT_NEAR(kTau, (observed.stamp - stamp).toSec(), 1e-9);
  expectClock(observed.stamp);

  spinFor(1.0);  // long enough for a second step to show, had the one answer made two
  EXPECT_TRUE(spinUntil([&] { return states_.size() > next + 1; })) << "the new state was not published again";
  for (std::size_t i = next; i < states_.size(); ++i)
  {
    EXPECT_EQ(observed.stamp, states_[i].header.stamp) << "one answer stepped more than once";
    EXPECT_EQ(states_[next].position, states_[i].position);
  }
}
}  // namespace
