// A real robot without a reset service (robot.launch): this node is the robot (the core's
// physics stepped at 100 Hz on the wall clock, holding the last command, states stamped with
// the wall time) and the person who, some time after each fall, stands the pole up again. The
// controller must end each episode on the fall, command zero through the gap, start the next
// episode only once the pole is up, and learn from no step of the gap.
#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/SaveQTable.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "ros_test_support.h"
#include "rostest_main.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <cmath>
#include <string>
#include <vector>

using namespace cartpole_qlearning;
using cartpole_qlearning::test::spinUntil;

namespace
{
// The controller's table folder, which the .test file gives this node too.
const cartpole_qlearning::test::ScratchFolder kTableDir("q_table_dir");
}  // namespace

TEST(RobotPerson, EpisodesStartWhenThePersonStandsThePoleUpAndTheGapsTeachNothing)
{
  ros::NodeHandle nh;
  double effort = 0.0;
  struct Command
  {
    ros::Time answers;
    double effort;
  };
  std::vector<Command> commands;
  ros::Subscriber command_sub = nh.subscribe<sensor_msgs::JointState>(
      "/my_robot/joint_command", 10000,
      boost::function<void(const sensor_msgs::JointStateConstPtr&)>([&](const sensor_msgs::JointStateConstPtr& m) {
        if (m->name.size() != 1 || m->name[0] != "cart_joint" || m->effort.size() != 1)
          return;
        effort = m->effort[0];
        commands.push_back({m->header.stamp, effort});
      }));
  std::vector<EpisodeStats> stats;
  ros::Subscriber stats_sub = nh.subscribe<EpisodeStats>(
      "/my_robot/episode_stats", 1000,
      boost::function<void(const EpisodeStatsConstPtr&)>([&](const EpisodeStatsConstPtr& m) { stats.push_back(*m); }));
  ros::Publisher state_pub = nh.advertise<sensor_msgs::JointState>("/my_robot/sensors/joint_states", 10);
  const ros::WallTime connect_deadline = ros::WallTime::now() + ros::WallDuration(30.0);
  // episode_stats too: a report lost before this node is connected would be missing from the sums below.
  while (ros::ok() &&
         (state_pub.getNumSubscribers() == 0 || command_sub.getNumPublishers() == 0 ||
          stats_sub.getNumPublishers() == 0) &&
         ros::WallTime::now() < connect_deadline)
  {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GT(state_pub.getNumSubscribers(), 0u) << "the controller never subscribed to the remapped joint_states";
  ASSERT_GT(stats_sub.getNumPublishers(), 0u) << "this node never connected to episode_stats";

  // The gaps, by the stamps of the states: from the first fallen state to the stand-up.
  struct Gap
  {
    ros::Time from;
    ros::Time to;  // zero while the pole is down
  };
  std::vector<Gap> gaps;
  CartPoleSimulation robot(CartPoleParams(), 0.05, 11);
  const CartPoleTask task;
  robot.resetRandom();
  const ros::WallDuration tick(0.01);
  ros::WallTime stand_up_at;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(60.0);
  bool down = false;
  while (ros::ok() && ros::WallTime::now() < deadline)
  {
    // The robot: publish the state, then hold the last command for one tick of physics.
    sensor_msgs::JointState msg;
    msg.header.stamp = ros::Time::now();
    msg.name = {"cart_joint", "pole_joint"};
    const CartPoleState& s = robot.state();
    msg.position = {s[0], s[2]};
    msg.velocity = {s[1], s[3]};
    msg.effort = {robot.appliedForce(), 0.0};
    if (!down && task.isTerminal(s))
    {
      down = true;
      gaps.push_back({msg.header.stamp, ros::Time()});
      stand_up_at = ros::WallTime::now() + ros::WallDuration(0.5);
    }
    state_pub.publish(msg);
    tick.sleep();
    ros::spinOnce();
    if (down && stats.size() >= 5 && ros::WallTime::now() > stand_up_at)
      break;  // five episodes, and the last gap seen through: enough
    if (down && ros::WallTime::now() >= stand_up_at)
    {
      // The person stands the pole up, near the middle of the track and still.
      robot.resetRandom();
      gaps.back().to = ros::Time::now();
      down = false;
      continue;
    }
    robot.step(effort);
    if (std::fabs(robot.state()[2]) > 1.5)  // the pole rests on the cart
      robot.reset(CartPoleState(robot.state()[0], 0.0, std::copysign(1.5, robot.state()[2]), 0.0));
  }
  // What the controller learnt, and (once they are all here) the episodes it reported: the pole
  // is down and the robot silent now, so no episode ends after this save.
  std::string dir;
  ASSERT_TRUE(ros::param::get("/my_robot/qlearning_controller/q_table_dir", dir));
  SaveQTable save;
  save.request.path = "after.yaml";
  ASSERT_TRUE(ros::service::call("/my_robot/qlearning_controller/save_q_table", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  const QTable table = loadQTableFile(dir + "/after.yaml");
  spinUntil([&] { return stats.size() >= table.episodes; }, 10.0);
  ASSERT_GE(stats.size(), 5u) << "the controller did not start episode after episode";

  // Through every gap the controller commanded zero, and it did command.
  std::size_t in_gaps = 0;
  std::size_t pushing = 0;
  for (const Command& c : commands)
  {
    for (const Gap& g : gaps)
    {
      if (c.answers >= g.from && (g.to.isZero() || c.answers < g.to))
      {
        ++in_gaps;
        pushing += c.effort != 0.0;
      }
    }
  }
  EXPECT_GT(in_gaps, 0u) << "no command answered a state of the gaps: the controller must keep commanding 0";
  EXPECT_EQ(0u, pushing) << "the controller pushed while the pole was down";

  // Every episode ended by a fall, and the table learnt exactly their steps: none of the gaps'.
  std::uint64_t episode_steps = 0;
  for (const EpisodeStats& s : stats)
  {
    EXPECT_TRUE(s.terminated) << "episode " << s.episode << " did not end by a fall";
    episode_steps += s.steps;
  }
  EXPECT_EQ(episode_steps, table.steps) << "steps were learnt outside the episodes";
  EXPECT_EQ(stats.size(), table.episodes);
}
