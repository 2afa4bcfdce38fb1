// A table is a controller (table_alone.test): evaluated with no config, through robot.launch and evaluate.launch,
// it runs with the configuration its file carries, in episodes of the evaluation's own length rather than the
// training's; a config that contradicts it is refused with both values and both sources named.
#include "cartpole_qlearning/LoadQTable.h"
#include "cartpole_qlearning/SaveQTable.h"

#include "rostest_main.h"
#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <fstream>
#include <string>

using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::TrainLaunch;
namespace text_match = cartpole_qlearning::test::text_match;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");

// The launch's output once it has ended by itself (its status in `status`).
std::string launchOutput(const std::string& home, const std::string& name, const std::string& args,
                         const std::string& launch_file, int& status)
{
  TrainLaunch launch(home, name, args, launch_file);
  status = launch.waitFor(90.0);
  return launch.output();
}

// The horizon the verdict names ("EVALUATED 3 episodes: B balanced to the step limit (N steps)"), -1 when none.
long verdictSteps(const std::string& output, unsigned episodes)
{
  text_match::Groups m;
  if (!text_match::contains(
          output,
          "EVALUATED " + std::to_string(episodes) + " episodes: [0-9]+ balanced to the step limit \\(([0-9]+) steps\\)",
          &m))
    return -1;
  return std::stol(m[1]);
}
}  // namespace

TEST(TableAlone, RobotAndEvaluateLaunchRunATableWithItsOwnConfigurationInTheEvaluationsEpisodes)
{
  const std::string home = kRosHome.path();
  ASSERT_FALSE(home.empty());
  std::filesystem::create_directories(home);
  // Trained in episodes of 200 steps: the config's task/max_episode_steps, which the evaluation must not take.
  const std::string config = home + "/short_episodes.yaml";
  std::ofstream(config) << "task:\n  max_episode_steps: 200\n  solved_mean_return: 195\n";
  const auto trained = runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --config " + config +
                                  " --seed 0 --quiet --no-run-folder --save q_table.yaml");
  ASSERT_EQ(0, trained.status) << trained.output;
  ASSERT_EQ(0u, trained.lastLine().find("until=solved reached=true solved=true ")) << trained.output;
  const std::string table = home + "/cartpole_qlearning/cartpole/q_table.yaml";

  // robot.launch with no config: the table's own, in 500-step episodes; no episode ends balanced at 200.
  const std::string robot =
      "mode:=evaluate load:=q_table.yaml episodes:=3 freshness_timeout:=0 "
      "reset_service:=cartpole_sim/reset";
  int status = -1;
  const std::string alone = launchOutput(home, "alone", robot, "robot.launch", status);
  EXPECT_EQ(0, status) << alone;
  EXPECT_NE(std::string::npos,
            alone.find("in episodes of 500 steps with the table's own configuration (" + table + ")"))
      << alone;
  EXPECT_EQ(500, verdictSteps(alone, 3)) << alone;
  EXPECT_FALSE(text_match::contains(alone, "evaluation episode [0-9]+: 200 steps, return [-0-9.]+, balanced")) << alone;

  // Its own length when told.
  const std::string shorter = launchOutput(home, "shorter", robot + " max_steps:=150", "robot.launch", status);
  EXPECT_EQ(0, status) << shorter;
  EXPECT_EQ(150, verdictSteps(shorter, 3)) << shorter;

  // A config that contradicts the table stops the controller, naming both.
  const std::string tiles = CARTPOLE_CONFIG_DIR "/tiles.yaml";
  const std::string refused = launchOutput(home, "refused", robot + " config:=" + tiles, "robot.launch", status);
  EXPECT_NE(std::string::npos,
            refused.find("learning/features is tiles in parameter server (/cartpole) but bins in the table " + table))
      << refused;
  EXPECT_EQ(-1, verdictSteps(refused, 3)) << refused;

  // evaluate.launch with its own sim, in a namespace of its own: the same, no config.
  const std::string own_home = home + "/evaluate";
  std::filesystem::create_directories(own_home + "/cartpole_qlearning/own");
  std::filesystem::copy_file(table, own_home + "/cartpole_qlearning/own/q_table.yaml");
  const std::string evaluated =
      launchOutput(own_home, "evaluate", "ns:=own mode:=lockstep episodes:=2", "evaluate.launch", status);
  EXPECT_EQ(0, status) << evaluated;
  EXPECT_NE(std::string::npos, evaluated.find("with the table's own configuration")) << evaluated;
  EXPECT_EQ(500, verdictSteps(evaluated, 2)) << evaluated;
}

// A launch argument is the user's own (issue 30): evaluate.launch q_table:=/abs/path.yaml loads a table
// that lies outside the table folder (as train_headless --save /abs/path.yaml writes it). The services
// stay confined to the folder: their caller is anyone on the graph.
TEST(TableAlone, EvaluateLaunchLoadsAnAbsoluteTableWhileItsServicesStayInTheFolder)
{
  const std::string home = kRosHome.path() + "/absolute";
  const std::string elsewhere = kRosHome.path() + "/elsewhere";
  std::filesystem::create_directories(home);
  std::filesystem::create_directories(elsewhere);
  const std::string table = elsewhere + "/mine.yaml";
  const auto trained =
      runCommand("ROS_HOME=" + home + " " + TRAIN_HEADLESS + " --seed 0 --quiet --no-run-folder --save " + table);
  ASSERT_EQ(0, trained.status) << trained.output;
  ASSERT_TRUE(std::filesystem::exists(table)) << trained.output;

  // Two episodes and a verdict: the launch ends by itself, having loaded the table where it lies.
  int status = -1;
  const std::string evaluated = launchOutput(
      home, "absolute", "ns:=absolute mode:=lockstep episodes:=2 q_table:=" + table, "evaluate.launch", status);
  EXPECT_EQ(0, status) << evaluated;
  EXPECT_NE(std::string::npos, evaluated.find("loaded " + table + " (259 episodes, 61681 steps of training)"))
      << evaluated;
  EXPECT_NE(std::string::npos, evaluated.find("with the table's own configuration (" + table + ")")) << evaluated;
  EXPECT_EQ(500, verdictSteps(evaluated, 2)) << evaluated;
  EXPECT_EQ(std::string::npos, evaluated.find("outside")) << evaluated;

  // Running on (episodes:=0), its services refuse that same absolute path, both ways.
  TrainLaunch running(home, "absolute_services", "ns:=services mode:=lockstep episodes:=0 q_table:=" + table,
                      "evaluate.launch");
  const std::string load_name = "/services/qlearning_controller/load_q_table";
  const std::string save_name = "/services/qlearning_controller/save_q_table";
  ASSERT_TRUE(ros::service::waitForService(load_name, ros::Duration(60.0))) << running.output();
  ASSERT_TRUE(ros::service::waitForService(save_name, ros::Duration(10.0))) << running.output();
  const std::string before = cartpole_qlearning::test::fileText(table);
  cartpole_qlearning::LoadQTable load;
  load.request.path = table;
  ASSERT_TRUE(ros::service::call(load_name, load));
  EXPECT_FALSE(load.response.success);
  EXPECT_NE(std::string::npos, load.response.message.find("is outside")) << load.response.message;
  cartpole_qlearning::SaveQTable save;
  save.request.path = elsewhere + "/written.yaml";
  ASSERT_TRUE(ros::service::call(save_name, save));
  EXPECT_FALSE(save.response.success);
  EXPECT_NE(std::string::npos, save.response.message.find("nothing written")) << save.response.message;
  EXPECT_FALSE(std::filesystem::exists(elsewhere + "/written.yaml"));
  EXPECT_EQ(before, cartpole_qlearning::test::fileText(table));
}
