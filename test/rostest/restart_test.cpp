// A sim or a controller that dies and comes back: training goes on in lockstep (the sim's
// repeats reach the new controller; the controller notices the silent sim, reconnects its
// reset client and starts a new episode on the restarted sim's states). All the while another
// node (this test) subscribes to joint_command: nothing may depend on who listens.
#include "cartpole_qlearning/EpisodeStats.h"
#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/JointState.h>

#include <filesystem>
#include <string>
#include <vector>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

using cartpole_qlearning::test::ChildProcess;
using cartpole_qlearning::test::pidOf;
using cartpole_qlearning::test::spinUntil;

namespace
{
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");

std::string tableDir()
{
  return kTableDir.path();
}
}  // namespace

TEST(Restart, TrainingGoesOnAfterTheSimAndTheControllerRestart)
{
  ros::NodeHandle nh;
  std::size_t episodes = 0;
  bool silent_reported = false;
  ros::Subscriber stats = nh.subscribe<cartpole_qlearning::EpisodeStats>(
      "/restart/episode_stats", 1000,
      boost::function<void(const cartpole_qlearning::EpisodeStatsConstPtr&)>(
          [&](const cartpole_qlearning::EpisodeStatsConstPtr&) { ++episodes; }));
  std::size_t commands = 0;
  ros::Subscriber listener =
      nh.subscribe<sensor_msgs::JointState>("/restart/joint_command", 1000,
                                            boost::function<void(const sensor_msgs::JointStateConstPtr&)>(
                                                [&](const sensor_msgs::JointStateConstPtr&) { ++commands; }));
  ros::Subscriber log = nh.subscribe<rosgraph_msgs::Log>(
      "/rosout", 1000,
      boost::function<void(const rosgraph_msgs::LogConstPtr&)>([&](const rosgraph_msgs::LogConstPtr& m) {
        silent_reported = silent_reported || m->msg.find("no joint_states") != std::string::npos;
      }));

  const std::vector<std::string> sim_args = {"__ns:=/restart", "__name:=cartpole_sim", "_mode:=lockstep",
                                             "_publish_tf:=false", "_lockstep_timeout:=0.3"};
  const std::vector<std::string> controller_args = {"__ns:=/restart",           "__name:=qlearning_controller",
                                                    "_sim_timeout:=1.0",        "_checkpoint_every:=0",
                                                    "_save_on_shutdown:=false", "_max_episodes:=1000000",
                                                    "_stop_when_solved:=false", "_q_table_dir:=" + tableDir()};
  ChildProcess sim(CARTPOLE_SIM, sim_args);
  ChildProcess controller(QLEARNING_CONTROLLER, controller_args);
  ASSERT_TRUE(spinUntil([&] { return episodes >= 20; }, 30.0)) << "training does not start: " << episodes;

  // The sim dies: the controller says so; a new sim comes and training goes on.
  sim.stop(SIGKILL);
  EXPECT_TRUE(spinUntil([&] { return silent_reported; }, 15.0)) << "the silent sim was not reported";
  sim = ChildProcess(CARTPOLE_SIM, sim_args);
  std::size_t seen = episodes;
  EXPECT_TRUE(spinUntil([&] { return episodes >= seen + 20; }, 30.0))
      << "training did not resume after the sim restarted: " << episodes - seen << " episodes";

  // The controller dies in the middle of an episode: a new one picks up the waiting state, and
  // training goes on within 5 s of its start (counted once it answers the master: how long a
  // process takes to get there is the machine's load, not the protocol's).
  EXPECT_GT(commands, 0u) << "this test's joint_command subscription heard nothing";
  controller.stop(SIGKILL);
  controller = ChildProcess(QLEARNING_CONTROLLER, controller_args);
  ASSERT_TRUE(spinUntil([&] { return pidOf("/restart/qlearning_controller") == controller.pid(); }, 30.0))
      << "the new controller did not come up";
  const ros::WallTime restarted = ros::WallTime::now();
  seen = episodes;
  EXPECT_TRUE(spinUntil([&] { return episodes >= seen + 2; }, 5.0))
      << "training did not resume within 5 s of the controller's restart: " << episodes - seen << " episodes";
  EXPECT_TRUE(spinUntil([&] { return episodes >= seen + 20; }, 30.0))
      << "training did not go on after the controller restarted: " << episodes - seen << " episodes in "
      << (ros::WallTime::now() - restarted).toSec() << " s";

  controller.stop(SIGINT);
  sim.stop(SIGINT);
}
