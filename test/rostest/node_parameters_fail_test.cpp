// Ko parameter fixtures, started by node_parameters_fail.test: each case puts one bad value on
// the parameter server under a namespace of its own and runs the real executable (or nodelet)
// there. The node must exit non-zero (not crash, not hang) with a message naming the parameter
// and the value. Ok cases, with valid values set the same way, prove the nodes read those
// namespaces and stay up, so the ko cases cannot pass vacuously. Only this wiring is checked
// here: the rules themselves are gtests of the nodes' ROS-free readers (test/node_settings/node_settings_test.cpp).
#include "cartpole_qlearning/simulation/physics_engines.h"

#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using XmlRpc::XmlRpcValue;

using cartpole_qlearning::test::CommandRun;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::runCommand;
using cartpole_qlearning::test::startProcess;
using cartpole_qlearning::test::stopProcess;
namespace text_match = cartpole_qlearning::test::text_match;

namespace
{
constexpr int kTimedOut = 124;  // timeout(1)'s status when the command outlived it

using Parameters = std::vector<std::pair<std::string, XmlRpcValue>>;  // names relative to the case's namespace

// Runs the executable in the namespace, stdout and stderr together, stopped with the signal
// after the given seconds (then killed 5 s later if it still runs).
CommandRun runNode(const std::string& executable, const std::string& ns, int seconds, const char* signal = "TERM")
{
  // timeout(1)'s status: the node's exit status, 124 when it was stopped, 128+n on signal n.
  return runCommand("timeout -k 5 -s " + std::string(signal) + " " + std::to_string(seconds) + " " + executable +
                    " __ns:=" + ns);
}

void setParameters(const std::string& ns, const Parameters& parameters)
{
  for (const auto& [name, value] : parameters)
    ros::param::set(ns + "/" + name, value);
}

XmlRpcValue list(const std::vector<XmlRpcValue>& values)
{
  XmlRpcValue array;
  array.setSize(static_cast<int>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i)
    array[static_cast<int>(i)] = values[i];
  return array;
}

// The node refuses: exits by itself, non-zero, without crashing, and says why on one line.
void expectRefused(const std::string& executable, const std::string& ns, const Parameters& parameters,
                   const std::string& says)
{
  setParameters(ns, parameters);
  const CommandRun run = runNode(executable, ns, 20);
  EXPECT_NE(0, run.status) << "the node accepted the parameters:\n" << run.output;
  EXPECT_NE(kTimedOut, run.status) << "the node did not exit within 20 s:\n" << run.output;
  // nodelet standalone exits with -1 (255) when its nodelet fails to load.
  EXPECT_TRUE(run.status > 0 && (run.status < 128 || run.status == 255))
      << "the node crashed (status " << run.status << "):\n"
      << run.output;
  EXPECT_TRUE(text_match::contains(run.output, says))
      << "the output does not name the parameter and its value (/" << says << "/):\n"
      << run.output;
}

// The node starts with the parameters, says so, and is still running a few seconds later. Its
// start takes what a loaded machine gives it (seconds under ASan): what it says is awaited, not
// assumed within a fixed time.
void expectRunning(const std::string& executable, const std::string& ns, const Parameters& parameters,
                   const std::vector<std::string>& says)
{
  setParameters(ns, parameters);
  const std::string log =
      (fs::temp_directory_path() / ("node_parameters_fail_" + std::to_string(::getpid()) + "_" + ns.substr(1) + ".log"))
          .string();
  // Line-buffered: its output is read while it runs.
  const pid_t pid = startProcess("/bin/sh", {"-c", "exec " + executable + " __ns:=" + ns + " >" + log + " 2>&1"},
                                 {"ROSCONSOLE_STDOUT_LINE_BUFFERED=1"});
  int status = 0;
  bool running = true;
  const auto stillRunning = [&] {
    if (running && ::waitpid(pid, &status, WNOHANG) == pid)
      running = false;
    return running;
  };
  const auto logAll = [&] {
    const std::string output = fileText(log);
    return std::all_of(says.begin(), says.end(),
                       [&](const std::string& text) { return text_match::contains(output, text); });
  };
  const auto wait = [](double seconds) { std::this_thread::sleep_for(std::chrono::duration<double>(seconds)); };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (stillRunning() && !logAll() && std::chrono::steady_clock::now() < deadline)
    wait(0.05);
  wait(3.0);
  const bool stayed_up = stillRunning();
  if (stayed_up)
  {
    ::kill(pid, SIGINT);
    for (int i = 0; i < 200 && stillRunning(); ++i)
      wait(0.05);
    if (running)
      stopProcess(pid, SIGKILL);
  }
  const std::string output = fileText(log);
  fs::remove(log);
  EXPECT_TRUE(stayed_up) << "the node stopped by itself (status "
                         << (WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)) << "):\n"
                         << output;
  EXPECT_EQ(std::string::npos, output.find("not allowed")) << output;
  for (const std::string& text : says)
    EXPECT_TRUE(text_match::contains(output, text))
        << "the output does not show the parameters were read (/" << text << "/):\n"
        << output;
}

class NodeParametersTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("node_parameters_fail_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  fs::path dir_;
};

const std::string kSim = CARTPOLE_SIM;
const std::string kController = QLEARNING_CONTROLLER;
// The nodelets, each alone in a process of its own, named as the executables are.
const std::string kSimNodelet =
    "rosrun nodelet nodelet standalone cartpole_qlearning/CartPoleSimNodelet __name:=cartpole_sim";
const std::string kControllerNodelet =
    "rosrun nodelet nodelet standalone cartpole_qlearning/QLearningControllerNodelet __name:=qlearning_controller";

// cartpole_sim

TEST_F(NodeParametersTest, SimRunsWithValidParametersFromItsNamespace)
{
  expectRunning(kSim, "/ok_sim",
                {{"cartpole_sim/mode", XmlRpcValue("lockstep")},
                 {"cartpole_sim/effort_limit", XmlRpcValue(5.0)},
                 {"physics/mass_pole", XmlRpcValue(0.2)},
                 {"physics/tau", XmlRpcValue(0.01)},
                 {"physics/integrator", XmlRpcValue("rk4")}},
                {"lockstep mode, tau 0.01 s, integrator rk4"});
}

TEST_F(NodeParametersTest, SimRefusesAnUnknownMode)
{
  expectRefused(kSim, "/ko_sim_mode", {{"cartpole_sim/mode", XmlRpcValue("warp")}}, "[/~]mode\\b.*\\bwarp\\b");
}

TEST_F(NodeParametersTest, SimNodeletRefusesAnUnknownMode)
{
  expectRefused(kSimNodelet, "/ko_sim_nodelet_mode", {{"cartpole_sim/mode", XmlRpcValue("warp")}},
                "[/~]mode\\b.*\\bwarp\\b");
}

// A MuJoCo model (physics/engine mujoco): relative to the folder of config_file, which the launch
// files set beside the config they load; one that cannot serve stops the sim naming the key and the model.
const std::string kModelConfig = CARTPOLE_CONFIG_DIR "/mujoco_cartpole.yaml";

Parameters modelPhysics(const std::string& model)
{
  return {{"physics/engine", XmlRpcValue("mujoco")},
          {"physics/model", XmlRpcValue(model)},
          {"physics/cart_joint", XmlRpcValue("cart_joint")},
          {"physics/pole_joint", XmlRpcValue("pole_joint")},
          {"physics/actuator", XmlRpcValue("cart_motor")}};
}

TEST_F(NodeParametersTest, SimStepsAMujocoModelRelativeToTheConfigFile)
{
  if (!cartpole_qlearning::mujocoAvailable())
  {
    // Without MuJoCo the sim says how to get it.
    expectRefused(kSim, "/ko_sim_no_mujoco", modelPhysics("../mjcf/cartpole.xml"),
                  "physics/engine = 'mujoco' is not available: cartpole_qlearning was built without MuJoCo");
    return;
  }
  Parameters parameters = modelPhysics("../mjcf/cartpole.xml");
  parameters.push_back({"config_file", XmlRpcValue(kModelConfig)});
  parameters.push_back({"cartpole_sim/mode", XmlRpcValue("lockstep")});
  expectRunning(kSim, "/ok_sim_mujoco", parameters,
                {"lockstep mode, tau 0.02 s, MuJoCo model " CARTPOLE_CONFIG_DIR "/../mjcf/cartpole.xml"});
}

TEST_F(NodeParametersTest, SimRefusesAMujocoModelThatCannotServe)
{
  if (!cartpole_qlearning::mujocoAvailable())
    GTEST_SKIP() << "built without MuJoCo (SimStepsAMujocoModelRelativeToTheConfigFile checks the message)";
  expectRefused(kSim, "/ko_sim_model", modelPhysics("/nonexistent/cartpole.xml"),
                "physics/model = '/nonexistent/cartpole.xml' cannot be loaded");
  // A relative model with no config_file to be relative to.
  expectRefused(kSim, "/ko_sim_model_relative", modelPhysics("../mjcf/cartpole.xml"),
                "physics/model = '../mjcf/cartpole.xml' cannot be loaded[\\s\\S]*the parameter "
                "/ko_sim_model_relative/config_file, which "
                "is not set");
  Parameters rail = modelPhysics("../mjcf/cartpole.xml");
  rail.push_back({"config_file", XmlRpcValue(kModelConfig)});
  rail.at(2).second = XmlRpcValue("rail");
  expectRefused(kSim, "/ko_sim_joint", rail, "physics/cart_joint = 'rail' in the model .*cartpole.xml: no such joint");
}

// qlearning_controller

TEST_F(NodeParametersTest, ControllerRunsWithValidParametersFromItsNamespace)
{
  expectRunning(kController, "/ok_controller",
                {{"qlearning_controller/mode", XmlRpcValue("train")},
                 {"qlearning_controller/seed", XmlRpcValue(3)},
                 {"qlearning_controller/checkpoint_every", XmlRpcValue(0)},
                 {"qlearning_controller/save_on_shutdown", XmlRpcValue(false)},
                 {"qlearning_controller/q_table_dir", XmlRpcValue(dir_.string())},
                 {"learning/gamma", XmlRpcValue(0.9)},
                 {"learning/bins", list({1, 1, 3, 4})}},
                {"training, seed 3, 12 states x 2 actions"});
  EXPECT_TRUE(fs::is_empty(dir_)) << "save_on_shutdown false, yet the controller wrote into " << dir_;
}

TEST_F(NodeParametersTest, ControllerRefusesAnUnknownMode)
{
  expectRefused(kController, "/ko_controller_mode", {{"qlearning_controller/mode", XmlRpcValue("fly")}},
                "[/~]mode\\b.*\\bfly\\b");
}

TEST_F(NodeParametersTest, ControllerNodeletRefusesAnUnknownMode)
{
  expectRefused(kControllerNodelet, "/ko_controller_nodelet_mode", {{"qlearning_controller/mode", XmlRpcValue("fly")}},
                "[/~]mode\\b.*\\bfly\\b");
}

TEST_F(NodeParametersTest, ControllerRefusesToPredictTheRobotsDelayWhileTraining)
{
  expectRefused(kController, "/ko_controller_predict_delay",
                {{"qlearning_controller/mode", XmlRpcValue("train")},
                 {"qlearning_controller/predict_delay_steps", XmlRpcValue(1)}},
                "[/~]predict_delay_steps = 1 is not allowed \\(only with mode evaluate or control");
}

// Not rules of the reader: the node opens these files as it starts.

TEST_F(NodeParametersTest, ControllerRefusesAMissingTableToLoadOnStart)
{
  expectRefused(kController, "/ko_controller_load",
                {{"qlearning_controller/q_table_dir", XmlRpcValue(dir_.string())},
                 {"qlearning_controller/load_on_start", XmlRpcValue("no_such_table.yaml")}},
                "no_such_table\\.yaml");
}

TEST_F(NodeParametersTest, ControllerRefusesAStatsCsvThatCannotBeOpened)
{
  fs::create_directories(dir_ / "a_folder");
  expectRefused(kController, "/ko_controller_stats_csv_folder",
                {{"qlearning_controller/q_table_dir", XmlRpcValue(dir_.string())},
                 {"qlearning_controller/stats_csv", XmlRpcValue((dir_ / "a_folder").string())}},
                "[/~]stats_csv\\b.*a_folder");
  EXPECT_FALSE(fs::exists(dir_ / "runs")) << "a refused controller started a run";
}
}  // namespace
