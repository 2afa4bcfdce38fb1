// The tutorial on the graph: roslaunch train.launch config:=tutorial_4_states.yaml trace:=true,
// as a learner runs it (sim and controller in lockstep). Each update the controller logs holds
// the tutorial's arithmetic (new = old + alpha * (target - old), target = r + gamma * max
// Q(next) unless the pole fell), and a table, equal to what the updates logged, ends each episode.
#include "ros_test_support.h"
#include "rostest_main.h"
#include "test_support.h"
#include "trace_check.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cartpole_qlearning::test::TraceReading;

namespace
{
const cartpole_qlearning::test::ScratchFolder kRosHome("ros_home");

std::string rosHome()
{
  return kRosHome.path();
}

// roslaunch train.launch ARGS to its end (at most 90 s; then Ctrl-C); its output, nodes included.
std::string launchToTheEnd(const std::string& name, const std::string& args, int& status)
{
  fs::create_directories(rosHome());
  cartpole_qlearning::test::TrainLaunch run(rosHome(), name, args);
  status = run.waitFor(90.0);
  return run.output();
}

const std::vector<std::string> kTutorialNames{"S1 tilted left", "S0 upright", "S2 tilted right", "S3 fallen"};
}  // namespace

TEST(ControllerTrace, TheTutorialsArithmeticHoldsOnTheRunningGraph)
{
  int status = -1;
  const std::string out = launchToTheEnd(
      "trace", "ns:=tutorial trace:=true max_episodes:=4 config:=" CARTPOLE_CONFIG_DIR "/tutorial_4_states.yaml",
      status);
  ASSERT_EQ(0, status) << out;
  const TraceReading trace(out, kTutorialNames);
  EXPECT_EQ(std::vector<std::string>(), trace.check(2, 0.9, 0.5)) << out;
  ASSERT_EQ(4u, trace.tables.size()) << out;
  for (std::size_t e = 0; e < trace.tables.size(); ++e)
    EXPECT_EQ("episode " + std::to_string(e + 1), trace.tables[e].title);
  // Every step of the 4 episodes is traced, steps numbered from 1 in each, the last one a fall
  // (the tutorial's 4 states cannot balance the pole to the step limit), then its table.
  ASSERT_FALSE(trace.updates.empty());
  std::size_t u = 0;
  for (std::size_t i = 0; i < trace.order.size(); ++i)
  {
    if (trace.order[i] == 't')
    {
      ASSERT_GT(u, 0u);
      EXPECT_TRUE(trace.updates[u - 1].terminal) << "a table after a step that did not fall";
      continue;
    }
    const auto& step = trace.updates[u];
    EXPECT_EQ(u == 0 || trace.updates[u - 1].terminal ? 1u : trace.updates[u - 1].step + 1, step.step);
    ++u;
  }
  EXPECT_EQ(4u, trace.updates.back().episode);
  EXPECT_NE(std::string::npos, out.find("NOT solved, max_episodes reached")) << out;
}

TEST(ControllerTrace, NoTraceUnlessAskedFor)
{
  int status = -1;
  const std::string out = launchToTheEnd(
      "quiet", "ns:=quiet max_episodes:=2 config:=" CARTPOLE_CONFIG_DIR "/tutorial_4_states.yaml", status);
  ASSERT_EQ(0, status) << out;
  const TraceReading trace(out, kTutorialNames);
  EXPECT_TRUE(trace.updates.empty()) << out;
  EXPECT_TRUE(trace.tables.empty()) << out;
}
