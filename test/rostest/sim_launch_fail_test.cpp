// The ko launch fixture: a sim with a bad parameter neither serves ~reset nor publishes, while
// the same launch with good parameters does both.
#include "ros_test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

using cartpole_qlearning::test::spinUntil;

TEST(SimLaunchFail, ABadParameterStopsTheSimAGoodOneDoesNot)
{
  ros::NodeHandle nh;
  int ok_states = 0;
  int ko_states = 0;
  ros::Subscriber ok =
      nh.subscribe<sensor_msgs::JointState>("/ok/joint_states", 10,
                                            boost::function<void(const sensor_msgs::JointStateConstPtr&)>(
                                                [&](const sensor_msgs::JointStateConstPtr&) { ++ok_states; }));
  ros::Subscriber ko =
      nh.subscribe<sensor_msgs::JointState>("/ko/joint_states", 10,
                                            boost::function<void(const sensor_msgs::JointStateConstPtr&)>(
                                                [&](const sensor_msgs::JointStateConstPtr&) { ++ko_states; }));
  // The good one comes up: the bad one has had the same time.
  ASSERT_TRUE(ros::service::waitForService("/ok/cartpole_sim/reset", ros::Duration(20.0)));
  ASSERT_TRUE(spinUntil([&] { return ok_states >= 10; }, 20.0));
  spinUntil([] { return false; }, 2.0);
  EXPECT_FALSE(ros::service::exists("/ko/cartpole_sim/reset", false)) << "the sim with ~mode warp serves ~reset";
  EXPECT_EQ(0, ko_states) << "the sim with ~mode warp publishes joint_states";
}
