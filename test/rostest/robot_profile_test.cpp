// A profile of config/robots/ on the graph, as a user tries it (test/rostest/robot_profile_*.test): try_robot.launch
// robot:=NAME, the sim posing as that cart-pole in lockstep and the controller of robot.launch robot:=NAME (in the
// .test, with a table folder) trains until solved; this node then runs `roslaunch cartpole_qlearning robot.launch
// robot:=NAME mode:=evaluate load:=q_table.yaml` against the same sim, as the user's next command, and reads its
// verdict. Private parameters: ros_home (the folder under which the training wrote its tables, ROS_HOME for the
// evaluation), robot (the profile), evaluate_args (what else the evaluation's command line needs: a reset for a
// robot that has none over ROS).
#include "cartpole_qlearning/EpisodeStats.h"
#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

using cartpole_qlearning::EpisodeStats;
using cartpole_qlearning::test::pidOf;
using cartpole_qlearning::test::privateParam;
using cartpole_qlearning::test::spinUntil;
using cartpole_qlearning::test::spinWhileProgressing;
using cartpole_qlearning::test::TrainLaunch;
namespace text_match = cartpole_qlearning::test::text_match;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");
const std::string kController = "/cartpole/qlearning_controller";
}  // namespace

TEST(RobotProfile, TrainsUntilSolvedThenTheTableIsEvaluated)
{
  const std::string robot = privateParam("robot");
  const std::string home = kRosHome.path();
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
  ASSERT_TRUE(spinWhileProgressing([&] { return !stats.empty() && stats.back().solved; }, [&] { return stats.size(); },
                                   30.0, 340.0))
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
  TrainLaunch evaluation(home, "evaluate",
                         // A lockstep sim holds no command: no freshness guard, as in the .test's training.
                         "robot:=" + robot + " mode:=evaluate load:=q_table.yaml episodes:=10 freshness_timeout:=0 " +
                             privateParam("evaluate_args"),
                         "robot.launch");
  const int status = evaluation.waitFor(120.0);
  const std::string output = evaluation.output();
  ASSERT_EQ(0, status) << output;
  text_match::Groups verdict;
  ASSERT_TRUE(text_match::contains(output,
                                   "EVALUATED 10 episodes: ([0-9]+) balanced to the step limit \\(500 steps\\), "
                                   "mean return ([0-9.]+)",
                                   &verdict))
      << output;
  std::printf("%s: %s\n", robot.c_str(), verdict[0].c_str());
  // The verdict is the ten episodes the evaluation printed: the same count balanced, the same mean return.
  std::map<unsigned, std::pair<unsigned, double>> episodes;  // episode -> steps, return
  unsigned balanced = 0;
  double returns = 0.0;
  for (const text_match::Groups& line : text_match::allMatches(
           output, "evaluation episode ([0-9]+): ([0-9]+) steps, return ([0-9.-]+), (fell|balanced)"))
  {
    episodes[std::stoul(line[1])] = {std::stoul(line[2]), std::stod(line[3])};
    balanced += line[4] == "balanced";
    returns += std::stod(line[3]);
  }
  ASSERT_EQ(10u, episodes.size()) << output;
  EXPECT_EQ(std::to_string(balanced), verdict[1]);
  EXPECT_NEAR(returns / 10.0, std::stod(verdict[2]), 0.051);
  // And what episode_stats published: greedy, the same episodes. (The first ones may be gone: this node
  // subscribes to the evaluation's controller only once it has started.)
  spinUntil([&] { return stats.size() >= 10u; }, 5.0);
  ASSERT_FALSE(stats.empty()) << "no episode_stats from the evaluation";
  for (const EpisodeStats& s : stats)
  {
    EXPECT_DOUBLE_EQ(0.0, s.epsilon) << "evaluation is greedy";
    ASSERT_EQ(1u, episodes.count(s.episode)) << "episode_stats of an episode not printed: " << s.episode;
    EXPECT_EQ(episodes[s.episode].first, s.steps);
    EXPECT_NEAR(episodes[s.episode].second, s.episode_return, 0.051);
  }
  // A learnt table, not a random one (which falls within about 20 steps): the pole is held up for most of the
  // episodes' length on average.
  EXPECT_GE(returns / 10.0, 250.0) << output;
}
