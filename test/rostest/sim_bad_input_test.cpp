// cartpole_sim in realtime mode, started by sim_bad_input.test, fed bad commands and bad resets:
// out-of-range efforts are clamped to the limit, NaN and Inf are refused, malformed resets are
// refused with a message, and the node stays up publishing finite states throughout.
#include "cartpole_qlearning/Reset.h"

#include "ros_test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace
{
constexpr double kEffortLimit = 8.0;   // sim_bad_input.test: below physics/force_mag (10 N)
constexpr double kWaitSeconds = 15.0;  // generous: the CI machine is loaded
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Observed
{
  std::vector<double> position;  // x, theta
  std::vector<double> velocity;  // x_dot, theta_dot
  double cart_effort = 0.0;
};

class SimBadInputTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    states_sub_ = nh_.subscribe("/cartpole/joint_states", 100, &SimBadInputTest::onJointState, this);
    effort_pub_ = nh_.advertise<std_msgs::Float64>("/cartpole/cart_effort", 10);
    reset_client_ = nh_.serviceClient<cartpole_qlearning::Reset>("/cartpole/cartpole_sim/reset");
    ASSERT_TRUE(ros::service::waitForService(reset_client_.getService(), ros::Duration(20.0)))
        << reset_client_.getService() << " never came up";
    ASSERT_TRUE(spinUntil([&] { return effort_pub_.getNumSubscribers() > 0 && !states_.empty(); }))
        << "the sim never connected to cart_effort or never published joint_states";
  }

  void TearDown() override
  {
    EXPECT_TRUE(problems_.empty()) << problems_.size() << " bad joint_states, the first: " << problems_.front();
  }

  // Every state must be finite with |effort| <= the limit; problems are reported at the end.
  void onJointState(const sensor_msgs::JointStateConstPtr& msg)
  {
    const auto index = [&](const char* name) {
      const auto it = std::find(msg->name.begin(), msg->name.end(), name);
      return it == msg->name.end() ? -1 : static_cast<int>(it - msg->name.begin());
    };
    const int cart = index("cart_joint");
    const int pole = index("pole_joint");
    const std::size_t n = msg->name.size();
    if (cart < 0 || pole < 0 || msg->position.size() != n || msg->velocity.size() != n || msg->effort.size() != n)
    {
      problems_.push_back("malformed joint_states");
      return;
    }
    Observed observed;
    observed.position = {msg->position[cart], msg->position[pole]};
    observed.velocity = {msg->velocity[cart], msg->velocity[pole]};
    observed.cart_effort = msg->effort[cart];
    for (const double value : {msg->position[cart], msg->position[pole], msg->velocity[cart], msg->velocity[pole],
                               msg->effort[cart], msg->effort[pole]})
    {
      if (!std::isfinite(value))
      {
        std::ostringstream out;
        out << "a non-finite value in " << *msg;
        problems_.push_back(out.str());
      }
    }
    if (std::fabs(msg->effort[cart]) > kEffortLimit || msg->effort[pole] != 0.0)
      problems_.push_back("effort beyond the limit: cart " + std::to_string(msg->effort[cart]) + ", pole " +
                          std::to_string(msg->effort[pole]));
    states_.push_back(observed);
  }

  bool spinUntil(const std::function<bool()>& done, double seconds = kWaitSeconds)
  {
    return cartpole_qlearning::test::spinUntil(done, seconds);
  }

  // Publishes the efforts in turn, one every 50 ms (well within the command timeout), until done.
  bool commandUntil(const std::vector<double>& efforts, const std::function<bool()>& done,
                    double seconds = kWaitSeconds)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
    for (std::size_t i = 0; ros::ok() && ros::WallTime::now() < deadline; ++i)
    {
      std_msgs::Float64 msg;
      msg.data = efforts[i % efforts.size()];
      effort_pub_.publish(msg);
      if (spinUntil(done, 0.05))
        return true;
    }
    return done();
  }

  // Holds the commands until `count` more states came; returns their efforts.
  std::vector<double> effortsWhileCommanding(const std::vector<double>& efforts, std::size_t count)
  {
    const std::size_t from = states_.size();
    EXPECT_TRUE(commandUntil(efforts, [&] { return states_.size() >= from + count; }))
        << "joint_states stopped while commanding";
    std::vector<double> seen;
    for (std::size_t i = from; i < states_.size(); ++i)
      seen.push_back(states_[i].cart_effort);
    return seen;
  }

  bool latestEffortIs(double effort) const
  {
    return !states_.empty() && states_.back().cart_effort == effort;
  }

  cartpole_qlearning::Reset::Response callReset(const std::vector<double>& state)
  {
    cartpole_qlearning::Reset reset;
    reset.request.state = state;
    EXPECT_TRUE(reset_client_.call(reset)) << "the reset call itself failed (the service must report, not fail)";
    return reset.response;
  }

  ros::NodeHandle nh_;
  ros::Subscriber states_sub_;
  ros::Publisher effort_pub_;
  ros::ServiceClient reset_client_;
  std::vector<Observed> states_;
  std::vector<std::string> problems_;
};

TEST_F(SimBadInputTest, OutOfRangeEffortsAreClampedToTheLimit)
{
  for (const double requested : {1e6, -1e6, 10.5, -kEffortLimit - 1e-6, kEffortLimit + 1.0})
  {
    SCOPED_TRACE("effort " + std::to_string(requested));
    const double limit = std::copysign(kEffortLimit, requested);
    ASSERT_TRUE(commandUntil({requested}, [&] { return latestEffortIs(limit); }))
        << "joint_states never showed the clamped effort " << limit;
    for (const double effort : effortsWhileCommanding({requested}, 20))
      EXPECT_EQ(limit, effort) << "while " << requested << " N was held";
  }
}

TEST_F(SimBadInputTest, NonFiniteEffortsAreRefused)
{
  ASSERT_TRUE(commandUntil({-1e6}, [&] { return latestEffortIs(-kEffortLimit); }));
  // Refused commands neither act nor renew the held one: it holds, then times out to zero.
  const std::size_t from = states_.size();
  EXPECT_TRUE(commandUntil({std::nan(""), kInf, -kInf}, [&] { return latestEffortIs(0.0); }))
      << "the held command never timed out while only NaN and Inf came";
  for (const double effort : effortsWhileCommanding({std::nan(""), kInf, -kInf}, 20))
    EXPECT_EQ(0.0, effort);
  for (std::size_t i = from; i < states_.size(); ++i)
    EXPECT_TRUE(states_[i].cart_effort == -kEffortLimit || states_[i].cart_effort == 0.0)
        << "effort " << states_[i].cart_effort << " while only NaN and Inf came";
  // A valid command is still taken.
  EXPECT_TRUE(commandUntil({5.0}, [&] { return latestEffortIs(5.0); }));
}

TEST_F(SimBadInputTest, MalformedResetsAreRefusedWithAMessage)
{
  const double nan = std::nan("");
  for (const std::vector<double>& bad :
       {std::vector<double>{0.01, 0.0, 0.02}, std::vector<double>{0.0, 0.0, nan, 0.0},
        std::vector<double>{kInf, 0.0, 0.0, 0.0}, std::vector<double>{0.0, 0.0, 0.0, -kInf},
        std::vector<double>{0.01, 0.0, 0.02, 0.0, 0.0}})
  {
    SCOPED_TRACE("a reset with " + std::to_string(bad.size()) + " values");
    const auto response = callReset(bad);
    EXPECT_FALSE(response.success);
    EXPECT_FALSE(response.message.empty()) << "a refusal must say why";
    if (bad.size() != 4)
    {
      EXPECT_NE(std::string::npos, response.message.find(std::to_string(bad.size()))) << response.message;
    }
  }

  // A valid reset still works, and its state is published exactly.
  const std::vector<double> start{0.01, -0.02, 0.03, -0.04};
  const auto response = callReset(start);
  EXPECT_TRUE(response.success) << response.message;
  EXPECT_TRUE(spinUntil([&] {
    return std::any_of(states_.begin(), states_.end(), [&](const Observed& s) {
      return s.position == std::vector<double>{start[0], start[2]} &&
             s.velocity == std::vector<double>{start[1], start[3]};
    });
  })) << "no joint_states carried the reset state";
}

TEST_F(SimBadInputTest, StaysUpAfterBadInput)
{
  commandUntil(
      {std::nan(""), 1e300, -kInf, -1e300, kInf}, [] { return false; }, 1.0);
  callReset(std::vector<double>(4, std::nan("")));
  callReset(std::vector<double>(100, 1.0));

  const auto response = callReset({});
  EXPECT_TRUE(response.success) << response.message;
  const std::size_t count = states_.size();
  EXPECT_TRUE(spinUntil([&] { return states_.size() >= count + 20; })) << "joint_states stopped";
}
}  // namespace
