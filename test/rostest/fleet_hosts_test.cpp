// One learner, three robots whose sims run as separate processes reached at three loopback
// addresses (127.0.0.1-3), as sims on other hosts would be. The address goes in ROS_HOSTNAME:
// roscpp takes a ROS_IP of 127.* as "this host only" and then listens on 127.0.0.1 alone, so a
// subscriber that dials 127.0.0.2 is refused (see the README's section on several hosts). One robot's sim is killed
// mid-training: the learner says so and goes on with the other two; the sim comes back (a new
// process, the same address) and the learner takes it into the rounds again.
#include "cartpole_qlearning/EpisodeStats.h"

#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>

#include <array>
#include <string>
#include <vector>

using cartpole_qlearning::EpisodeStats;
using cartpole_qlearning::EpisodeStatsConstPtr;
using cartpole_qlearning::test::ChildProcess;
using cartpole_qlearning::test::spinUntil;
using cartpole_qlearning::test::uriOf;

namespace
{
// The controller's table folder, which the .test file gives this node too.
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");
constexpr std::size_t kRobots = 3;

ChildProcess startSim(std::size_t robot)
{
  return ChildProcess(CARTPOLE_SIM,
                      {"__ns:=/fleet/robot_" + std::to_string(robot), "__name:=cartpole_sim", "_mode:=lockstep",
                       "_seed:=" + std::to_string(robot), "_publish_tf:=false", "_lockstep_timeout:=0.3"},
                      {"ROS_HOSTNAME=127.0.0." + std::to_string(robot + 1)});
}

}  // namespace

TEST(FleetHosts, TheLearnerGoesOnWithoutALostRobotAndTakesItBack)
{
  ros::NodeHandle nh;
  std::array<std::size_t, kRobots> episodes{};
  bool dropped_logged = false;
  bool back_logged = false;
  std::vector<ros::Subscriber> subs;
  for (std::size_t r = 0; r < kRobots; ++r)
    subs.push_back(nh.subscribe<EpisodeStats>("/fleet/robot_" + std::to_string(r) + "/episode_stats", 10000,
                                              boost::function<void(const EpisodeStatsConstPtr&)>(
                                                  [&episodes, r](const EpisodeStatsConstPtr&) { ++episodes[r]; })));
  ros::Subscriber log = nh.subscribe<rosgraph_msgs::Log>(
      "/rosout", 1000,
      boost::function<void(const rosgraph_msgs::LogConstPtr&)>([&](const rosgraph_msgs::LogConstPtr& m) {
        if (m->msg.find("robot_2/joint_states is silent; the rounds go on without it") != std::string::npos)
          dropped_logged = true;
        if (m->msg.find("robot_2/joint_states takes part in the rounds again") != std::string::npos)
          back_logged = true;
      }));

  // Stopped however the test ends.
  std::array<ChildProcess, kRobots> sims;
  for (std::size_t r = 0; r < kRobots; ++r)
    sims[r] = startSim(r);
  const auto all_at_least = [&](std::size_t n) { return episodes[0] >= n && episodes[1] >= n && episodes[2] >= n; };
  ASSERT_TRUE(spinUntil([&] { return all_at_least(20); }, 60.0))
      << "training with three robots does not run: " << episodes[0] << ", " << episodes[1] << ", " << episodes[2];
  // Each sim is reached at its own address, as on its own host.
  for (std::size_t r = 0; r < kRobots; ++r)
    EXPECT_NE(
        std::string::npos,
        uriOf("/fleet/robot_" + std::to_string(r) + "/cartpole_sim").find("//127.0.0." + std::to_string(r + 1) + ":"))
        << "robot_" << r << "'s sim is not bound to 127.0.0." << r + 1;

  // robot_2's host goes away: after sim_timeout (1 s) the learner leaves it out and goes on.
  sims[2].stop(SIGKILL);
  ASSERT_TRUE(spinUntil([&] { return dropped_logged; }, 15.0)) << "the learner did not say that robot_2 dropped out";
  const auto before = episodes;
  EXPECT_TRUE(spinUntil([&] { return episodes[0] >= before[0] + 20 && episodes[1] >= before[1] + 20; }, 30.0))
      << "the learner did not go on with robot_0 and robot_1: " << episodes[0] - before[0] << ", "
      << episodes[1] - before[1] << " episodes";
  EXPECT_EQ(before[2], episodes[2]) << "episodes of a dead robot";

  // It comes back: the learner takes it into the rounds again and its episodes go on.
  sims[2] = startSim(2);
  EXPECT_TRUE(spinUntil([&] { return back_logged && episodes[2] >= before[2] + 10; }, 30.0))
      << "robot_2 was not taken back: " << episodes[2] - before[2] << " episodes since";
  const auto after = episodes;
  EXPECT_TRUE(
      spinUntil([&] { return episodes[0] > after[0] && episodes[1] > after[1] && episodes[2] > after[2]; }, 30.0))
      << "not all three robots train together again";
}
