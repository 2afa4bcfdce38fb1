// A profile of config/robots/ on the graph, as a user runs it (test/robot_profile_*.test): the sim poses as that
// cart-pole in lockstep; the controller started by robot.launch robot:=NAME (in the .test, with a table folder and
// stop_when_solved) trains until solved; this node then runs `roslaunch cartpole_qlearning robot.launch robot:=NAME
// mode:=evaluate load:=q_table.yaml` against the same sim, as the user's next command, and reads its verdict.
// Private parameters: ros_home (the folder under which the training wrote its tables, ROS_HOME for the evaluation),
// robot (the profile), evaluate_args (what else the evaluation's command line needs: a reset for a robot that has
// none over ROS).
#include "cartpole_qlearning/EpisodeStats.h"
#include "ros_test_support.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

using cartpole_qlearning::EpisodeStats;
using cartpole_qlearning::test::pidOf;
using cartpole_qlearning::test::privateParam;
using cartpole_qlearning::test::spinUntil;
using cartpole_qlearning::test::TrainLaunch;

namespace
{
const std::string kController = "/cartpole/qlearning_controller";
}  // namespace

TEST(RobotProfile, TrainsUntilSolvedThenTheTableIsEvaluated)
{
  const std::string robot = privateParam("robot");
  const std::string home = privateParam("ros_home");
  ASSERT_FALSE(robot.empty());
  ASSERT_FALSE(home.empty());
  ros::NodeHandle nh;
  std::vector<EpisodeStats> stats;
  ros::Subscriber stats_sub =
      nh.subscribe<EpisodeStats>("/cartpole/episode_stats", 10000,
                                 boost::function<void(const cartpole_qlearning::EpisodeStatsConstPtr&)>(
                                     [&](const cartpole_qlearning::EpisodeStatsConstPtr& m) { stats.push_back(*m); }));

  // Training: robot.launch's controller ends itself at the first solved episode (stop_when_solved), having saved
  // the default table.
  ASSERT_TRUE(spinUntil([&] { return !stats.empty() && stats.back().solved; }, 240.0))
      << robot << ": not solved; episodes seen: " << stats.size()
      << (stats.empty() ? "" : ", the last mean return " + std::to_string(stats.back().mean_return_100));
  const EpisodeStats solved = stats.back();
  EXPECT_GE(solved.mean_return_100, 475.0);
  ASSERT_TRUE(spinUntil([&] { return pidOf(kController) < 0; }, 60.0)) << "the controller did not end when solved";
  const std::string table = home + "/cartpole_qlearning/cartpole/q_table.yaml";
  ASSERT_TRUE(std::filesystem::exists(table)) << table;
  std::printf("%s: SOLVED after %u episodes, %llu steps\n", robot.c_str(), solved.episode,
              static_cast<unsigned long long>(solved.total_steps));

  // Evaluation: the user's next command, against the same robot (the sim waits on its pending state).
  stats.clear();
  TrainLaunch evaluation(
      home, "evaluate",
      "robot:=" + robot + " mode:=evaluate load:=q_table.yaml episodes:=10 " + privateParam("evaluate_args"),
      "robot.launch");
  const int status = evaluation.waitFor(120.0);
  const std::string output = evaluation.output();
  ASSERT_EQ(0, status) << output;
  std::smatch verdict;
  ASSERT_TRUE(
      std::regex_search(output, verdict,
                        std::regex("EVALUATED 10 episodes: ([0-9]+) balanced to the step limit \\(500 steps\\), "
                                   "mean return ([0-9.]+)")))
      << output;
  std::printf("%s: %s\n", robot.c_str(), verdict[0].str().c_str());
  // The verdict is the episodes the evaluation published: the same count balanced.
  spinUntil([&] { return stats.size() >= 10u; }, 5.0);
  ASSERT_EQ(10u, stats.size()) << output;
  unsigned balanced = 0;
  double returns = 0.0;
  for (const EpisodeStats& s : stats)
  {
    EXPECT_DOUBLE_EQ(0.0, s.epsilon) << "evaluation is greedy";
    balanced += s.truncated && !s.terminated;
    returns += s.episode_return;
  }
  EXPECT_EQ(std::to_string(balanced), verdict[1].str());
  EXPECT_NEAR(returns / 10.0, std::stod(verdict[2].str()), 0.051);
  // A learnt table, not a random one (which falls within about 20 steps): the pole is held up for most of the
  // episodes' length on average.
  EXPECT_GE(returns / 10.0, 250.0) << output;
}

int main(int argc, char** argv)
{
  return cartpole_qlearning::test::runTestsRemovingRosHome(argc, argv, "robot_profile_test");
}
