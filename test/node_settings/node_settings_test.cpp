// The nodes' private parameters, read by the core from YAML text as the nodes read them from the
// parameter server: every rule, default and message without a master. (node_parameters_fail.test
// checks only that a refusal stops each executable.)
#include "cartpole_qlearning/node_settings/controller_settings.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/node_settings/sim_settings.h"
#include "cartpole_qlearning/node_settings/table_folder.h"

#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

using namespace cartpole_qlearning;

namespace
{
const char* const kController = "/cartpole/qlearning_controller";
const char* const kSim = "/cartpole/cartpole_sim";

// A stand-in for ros::names::validate: names of letters, digits, _ and / that start with a letter.
std::string nameError(const std::string& name)
{
  if (!std::isalpha(static_cast<unsigned char>(name.front())))
    return "must start with a letter";
  for (const char c : name)
  {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '/')
      return std::string("'") + c + "' is not allowed in a name";
  }
  return "";
}

ControllerContext context()
{
  ControllerContext context;
  context.name_space = "/cartpole";
  context.home = "/home/user";
  context.name_error = nameError;
  context.other_keys = {"epsilon_override", "gamma"};
  return context;
}

ControllerSettings readController(const std::string& priv, const std::string& shared = "",
                                  const ControllerContext& with = context())
{
  return readControllerSettings(*parseYamlParameters(shared, "/cartpole"), *parseYamlParameters(priv, kController),
                                with);
}

// The message of the ConfigError the reader throws, or "" when it accepts the parameters.
std::string controllerError(const std::string& priv, const std::string& shared = "",
                            const ControllerContext& with = context())
{
  try
  {
    readController(priv, shared, with);
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}

SimSettings readSim(const std::string& priv, const std::string& shared = "")
{
  return readSimSettings(*parseYamlParameters(shared, "/cartpole"), *parseYamlParameters(priv, kSim));
}

std::string simError(const std::string& priv, const std::string& shared = "")
{
  try
  {
    readSim(priv, shared);
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}

// The message says `what` (the parameter, its value and what is allowed).
#define EXPECT_SAYS(message, what) EXPECT_NE(std::string::npos, (message).find(what)) << (message)
}  // namespace

// qlearning_controller

TEST(ControllerSettings, DefaultsAreTheDocumentedOnes)
{
  const ControllerSettings s = readController("");
  EXPECT_TRUE(s.run.learning());
  EXPECT_EQ(0u, s.run.seed);
  EXPECT_EQ("/cartpole", s.run.name_space);
  EXPECT_EQ(defaultTableDirectory("/cartpole"), s.run.q_table_dir);
  EXPECT_EQ("q_table.yaml", s.run.q_table_path);
  EXPECT_EQ("", s.run.load_on_start);
  EXPECT_EQ("", s.run.stats_csv);
  EXPECT_EQ("", s.run.run_id);
  EXPECT_EQ(10u, s.run.evaluation_episodes);
  EXPECT_EQ(100u, s.run.checkpoint_every);
  EXPECT_TRUE(s.run.save_on_shutdown);
  EXPECT_FALSE(s.run.trace);
  EXPECT_TRUE(s.shutdown_when_finished);
  EXPECT_EQ(2.0, s.sim_timeout);
  EXPECT_EQ("cartpole_sim/reset", s.reset_service);
  EXPECT_TRUE(s.protocol.reset_service);
  EXPECT_EQ(std::vector<std::string>{""}, s.robots);
  EXPECT_TRUE(s.sync);
  // The start region defaults to the random starts' bound; the limits are training/'s.
  EXPECT_EQ(CartPoleState::Constant(0.05), s.protocol.start_region);
  EXPECT_EQ(1000u, s.protocol.limits.max_episodes);
  EXPECT_TRUE(s.protocol.limits.stop_when_solved);
}

TEST(ControllerSettings, ANodeletDoesNotEndItsManagerUnlessAsked)
{
  ControllerContext nodelet = context();
  nodelet.shutdown_by_default = false;
  EXPECT_FALSE(readController("", "", nodelet).shutdown_when_finished);
  EXPECT_TRUE(readController("shutdown_when_finished: true", "", nodelet).shutdown_when_finished);
}

TEST(ControllerSettings, ReadsValidParametersAndTheSharedSections)
{
  // node_parameters_fail.test's ok fixture.
  const ControllerSettings s =
      readController("{mode: train, seed: 3, checkpoint_every: 0, save_on_shutdown: false, q_table_dir: /tmp/t}",
                     "learning: {gamma: 0.9, bins: [1, 1, 3, 4]}");
  EXPECT_TRUE(s.run.learning());
  EXPECT_EQ(3u, s.run.seed);
  EXPECT_EQ(0u, s.run.checkpoint_every);
  EXPECT_FALSE(s.run.save_on_shutdown);
  EXPECT_EQ("/tmp/t", s.run.q_table_dir);
  EXPECT_EQ(0.9, s.training.agent.gamma);
  EXPECT_EQ(3u, s.training.agent.discretiser.bins[2]);

  // (With a configuration beside it: the table is opened when the run starts, not here.)
  const ControllerSettings e = readController(
      "{mode: evaluate, evaluation_episodes: 0, sim_timeout: 0.5, reset_service: '', sync: false, trace: true, "
      "run_id: abc, load_on_start: t.yaml, stats_csv: none, start_region: [1, 2, 0.1, 0.2]}",
      "learning: {gamma: 0.9}");
  EXPECT_FALSE(e.run.learning());
  EXPECT_EQ(0u, e.run.evaluation_episodes);
  EXPECT_EQ(0.5, e.sim_timeout);
  EXPECT_FALSE(e.protocol.reset_service);
  EXPECT_FALSE(e.sync);
  EXPECT_TRUE(e.run.trace);
  EXPECT_EQ("abc", e.run.run_id);
  EXPECT_EQ("t.yaml", e.run.load_on_start);
  EXPECT_EQ("none", e.run.stats_csv);
  EXPECT_EQ(CartPoleState(1, 2, 0.1, 0.2), e.protocol.start_region);
}

TEST(ControllerSettings, PrivateLimitsOverrideTheSharedOnes)
{
  const ControllerSettings s =
      readController("{max_episodes: 7, stop_when_solved: false}", "training: {max_episodes: 50}");
  EXPECT_EQ(7u, s.training.limits.max_episodes);
  EXPECT_FALSE(s.training.limits.stop_when_solved);
  EXPECT_EQ(7u, s.protocol.limits.max_episodes);
  EXPECT_FALSE(s.protocol.limits.stop_when_solved);
  EXPECT_SAYS(controllerError("max_episodes: 0"),
              "qlearning_controller: max_episodes = 0 is not allowed (must be a whole number >= 1)");
}

TEST(ControllerSettings, ControlDrivesWithATableAndNoStepLimitNorVerdict)
{
  const std::string shared = "{task: {max_episode_steps: 200}}";
  const ControllerSettings control = readController("{mode: control, load_on_start: robust.yaml}", shared);
  EXPECT_TRUE(control.run.controlling());
  EXPECT_FALSE(control.run.learning());
  EXPECT_EQ(std::numeric_limits<unsigned>::max(), control.training.task.max_episode_steps);
  EXPECT_EQ(0u, control.run.evaluation_episodes);
  EXPECT_EQ(10.0, control.run.report_every);
  // A gap between two decisions counts at most the freshness bound (0.1 s: five 20 ms periods).
  EXPECT_DOUBLE_EQ(0.1, control.run.control_max_gap);
  EXPECT_DOUBLE_EQ(
      2.0,
      readController("{mode: control, load_on_start: t.yaml, freshness_timeout: 2.0}", shared).run.control_max_gap);
  EXPECT_EQ(2.5, readController("{mode: control, load_on_start: t.yaml, report_every: 2.5}", shared).run.report_every);
  EXPECT_FALSE(readController("mode: evaluate", shared).run.controlling());
  // What control cannot take, each refused naming it.
  EXPECT_SAYS(controllerError("mode: control", shared),
              "mode = control is not allowed (needs ~load_on_start: a trained table to drive the robot with)");
  EXPECT_SAYS(controllerError("{mode: control, load_on_start: t.yaml, max_steps: 500}", shared),
              "max_steps = 500 is not allowed (not with mode control, which has no step limit");
  EXPECT_SAYS(controllerError("{mode: control, load_on_start: t.yaml, report_every: 0}", shared), "report_every = 0");
  EXPECT_SAYS(controllerError("{mode: evaluate, report_every: 5}", shared),
              "report_every = 5 is not allowed (only with mode control)");
}

TEST(ControllerSettings, APredictionOfTheRobotsDelayIsForAGreedyTable)
{
  const std::string shared = "{task: {max_episode_steps: 200}}";
  // Not told: a greedy table finds it from the robot's states; training never predicts.
  EXPECT_EQ(kDelayFoundFromStates,
            readController("{mode: control, load_on_start: t.yaml}", shared).run.predict_delay_steps);
  EXPECT_EQ(kDelayFoundFromStates, readController("{mode: evaluate}", shared).run.predict_delay_steps);
  EXPECT_EQ(0u, readController("{mode: train}", shared).run.predict_delay_steps);
  EXPECT_EQ(0u, readController("{mode: evaluate, predict_delay_steps: 0}", shared).run.predict_delay_steps);
  EXPECT_EQ(
      1u,
      readController("{mode: control, load_on_start: t.yaml, predict_delay_steps: 1}", shared).run.predict_delay_steps);
  EXPECT_EQ(2u, readController("{mode: evaluate, predict_delay_steps: 2}", shared).run.predict_delay_steps);
  EXPECT_EQ(0u, readController("{mode: train, predict_delay_steps: 0}", shared).run.predict_delay_steps);
  EXPECT_SAYS(controllerError("{mode: train, predict_delay_steps: 1}", shared),
              "predict_delay_steps = 1 is not allowed (only with mode evaluate or control: training learns from the "
              "states it observes)");
  EXPECT_SAYS(controllerError("{mode: evaluate, predict_delay_steps: 51}", shared), "predict_delay_steps = 51");
  EXPECT_SAYS(controllerError("{mode: evaluate, predict_delay_steps: -1}", shared), "predict_delay_steps = -1");
  // A step of the delay is a decision of physics/tau (0.02 s), as the model predicts it.
  EXPECT_EQ(1u, readController("{mode: evaluate, predict_delay_steps: 1, decision_period: 0.02}", shared)
                    .run.predict_delay_steps);
  EXPECT_SAYS(
      controllerError("{mode: evaluate, predict_delay_steps: 1, decision_period: 0.01}", shared),
      "predict_delay_steps = 1 is not allowed (the table's model predicts in decisions of physics/tau = 0.02 s: "
      "it needs ~decision_period = tau, not 0.01)");
  EXPECT_SAYS(controllerError("{mode: evaluate, predict_delay_steps: 1, decision_period: 0}", shared),
              "needs ~decision_period = tau, not 0)");
}

TEST(ControllerSettings, ARobotOwnersLimitBoundsEveryCommandWhateverTheTable)
{
  const std::string shared =
      "{task: {max_episode_steps: 200}, physics: {force_mag: 1000}, learning: {actions: [-1000, 1000]}}";
  const ControllerSettings limited = readController("{mode: control, load_on_start: t.yaml, max_effort: 12}", shared);
  EXPECT_EQ(12.0, limited.robot.max_effort);
  EXPECT_EQ(12.0, robotEffort(limited.robot, 1000.0));
  EXPECT_EQ(-12.0, robotEffort(limited.robot, -1000.0));
  EXPECT_EQ(5.0, robotEffort(limited.robot, 5.0));
  // The sign applies to the clamped effort: a robot whose + pushes toward -x.
  EXPECT_EQ(12.0,
            robotEffort(
                readController("{mode: control, load_on_start: t.yaml, max_effort: 12, effort_sign: -1}", shared).robot,
                -1000.0));
  for (const char* bad : {"0", "-5", ".nan"})
    EXPECT_SAYS(controllerError(std::string("{mode: control, load_on_start: t.yaml, max_effort: ") + bad + "}", shared),
                std::string("max_effort = ") + (std::string(bad) == ".nan" ? "nan" : bad) +
                    " is not allowed (must be > 0 N: the most effort the robot may be commanded (absent: no limit))");
  // Without one, control says once what goes out unbounded; with one, nothing.
  const ControllerSettings unlimited = readController("{mode: control, load_on_start: t.yaml}", shared);
  EXPECT_FALSE(std::isfinite(unlimited.robot.max_effort));
  ASSERT_EQ(1u, unlimited.warnings.size());
  EXPECT_EQ(
      "no ~max_effort: commands go out as the table's actions, up to 1000 N; give the robot's limit "
      "(robot.launch max_effort:=N) to bound every command",
      unlimited.warnings[0]);
  EXPECT_TRUE(limited.warnings.empty());
}

TEST(ControllerSettings, ControlRefusesTheFreshnessGuardOffUnlessTheRobotIsALockstepSim)
{
  const std::string shared = "{task: {max_episode_steps: 200}}";
  EXPECT_SAYS(controllerError("{mode: control, load_on_start: t.yaml, freshness_timeout: 0}", shared),
              "freshness_timeout = 0 is not allowed (mode control drives a robot that holds its last command: the "
              "guard that commands 0 when fresh states stop can be off only for a sim in lockstep "
              "(~robot_lockstep: true))");
  const ControllerSettings lockstep =
      readController("{mode: control, load_on_start: t.yaml, robot_lockstep: true}", shared);
  EXPECT_EQ(0.0, lockstep.freshness_timeout);
  EXPECT_EQ(0.0,
            readController("{mode: control, load_on_start: t.yaml, robot_lockstep: true, freshness_timeout: 0}", shared)
                .freshness_timeout);
  EXPECT_EQ(0.0, readController("{mode: evaluate, freshness_timeout: 0}", shared).freshness_timeout);
  EXPECT_EQ(0.0, readController("{mode: train, freshness_timeout: 0}", shared).freshness_timeout);
  // Control judges time going back by the state; training and evaluation take it for a restart.
  EXPECT_TRUE(lockstep.protocol.time_back_judged_by_state);
  EXPECT_FALSE(readController("{mode: evaluate}", shared).protocol.time_back_judged_by_state);
}

TEST(ControllerSettings, ValuesFarFromTheTablesStepAreWarnedOnceNamingBoth)
{
  const std::string shared = "{task: {max_episode_steps: 200}}";
  const std::string limit = ", max_effort: 10}";
  const auto warnings = [&](const std::string& priv) {
    return readController("{mode: control, load_on_start: t.yaml" + priv + limit, shared).warnings;
  };
  EXPECT_TRUE(warnings("").empty());
  EXPECT_TRUE(warnings(", decision_period: 0.025, freshness_timeout: 0.5, predict_delay_steps: 0").empty());
  // (The freshness bound follows the period: five of them, 5 s here, and is said too.)
  EXPECT_EQ((std::vector<std::string>{"~decision_period = 1 s is 50 times the table's step (physics/tau) of 0.02 s: "
                                      "the table decides as if 0.02 s passed between its decisions",
                                      "~freshness_timeout = 5 s is 250 times the table's step (physics/tau) of 0.02 "
                                      "s: when fresh states stop, the last command goes on pushing the robot that "
                                      "long before 0"}),
            warnings(", decision_period: 1"));
  EXPECT_EQ(std::vector<std::string>{"~freshness_timeout = 10 s is 500 times the table's step (physics/tau) of 0.02 "
                                     "s: when fresh states stop, the last command goes on pushing the robot that "
                                     "long before 0"},
            warnings(", freshness_timeout: 10"));
  EXPECT_EQ(std::vector<std::string>{"~predict_delay_steps = 50 predicts 1 s ahead at the table's step (physics/tau) "
                                     "of 0.02 s: a robot that late is rare; the prediction drifts from the robot the "
                                     "further it looks"},
            warnings(", predict_delay_steps: 50"));
  // Training says none of them: the table learns the step it is given.
  EXPECT_TRUE(readController("{mode: train, decision_period: 1}", shared).warnings.empty());
}

TEST(ControllerSettings, TheDefaultTableIsNamedAfterTheConfigSoThatNoConfigReplacesAnothers)
{
  EXPECT_EQ("q_table.yaml", readController("").run.q_table_path);
  EXPECT_EQ("q_table.yaml",
            readController("", "{config_file: /opt/share/cartpole_qlearning/config/cartpole.yaml}").run.q_table_path);
  EXPECT_EQ("q_table_robust.yaml", readController("", "{config_file: /x/config/robust.yaml}").run.q_table_path);
  EXPECT_EQ("q_table_mujoco_cartpole.yaml",
            readController("", "{config_file: /x/mujoco_cartpole.yaml}").run.q_table_path);
  // One given is the user's.
  EXPECT_EQ("mine.yaml", readController("{q_table_path: mine.yaml}", "{config_file: /x/robust.yaml}").run.q_table_path);
  EXPECT_EQ("q_table_swing.yaml", defaultTableName("swing.yml"));
  EXPECT_EQ("q_table.yaml", defaultTableName(""));
}

TEST(ControllerSettings, RefusesAnUnknownMode)
{
  EXPECT_SAYS(controllerError("mode: fly"), "mode = 'fly' is not allowed (allowed: train, evaluate, control)");
}

TEST(ControllerSettings, RefusesANegativeSeed)
{
  EXPECT_SAYS(controllerError("seed: -1"), "seed = -1 is not allowed (must be a whole number >= 0)");
}

TEST(ControllerSettings, RefusesANegativeCheckpointInterval)
{
  EXPECT_SAYS(controllerError("checkpoint_every: -5"),
              "checkpoint_every = -5 is not allowed (must be a whole number >= 0)");
  EXPECT_SAYS(controllerError("evaluation_episodes: -1"),
              "evaluation_episodes = -1 is not allowed (must be a whole number >= 0)");
}

TEST(ControllerSettings, RefusesBadSharedSections)
{
  EXPECT_SAYS(controllerError("", "learning: {gamma: 2.0}"), "learning/gamma = 2 is not allowed (must be in [0, 1])");
  EXPECT_SAYS(controllerError("", "learning: {bins: [1, 6, 12]}"),
              "learning/bins = [1, 6, 12] is not allowed (must list 4 values");
}

TEST(ControllerSettings, RefusesATraceOfTiles)
{
  EXPECT_SAYS(controllerError("trace: true", "learning: {features: tiles}"),
              "trace = true is not allowed (the trace shows one table row per state: learning/features bins only)");
  EXPECT_EQ("", controllerError("trace: false", "learning: {features: tiles}"));
}

TEST(ControllerSettings, RefusesAMisspeltPrivateParameter)
{
  const std::string error = controllerError("checkpoint_evry: 10");
  EXPECT_SAYS(error, "/cartpole/qlearning_controller: unknown key checkpoint_evry (known keys: ");
  EXPECT_SAYS(error, "checkpoint_every");
}

TEST(ControllerSettings, KnowsTheKeysItWritesAndThoseOfLiveTuning)
{
  // run/... is what the controller leaves for a respawn of itself; the others are the context's.
  EXPECT_EQ("", controllerError("{run: {id: a, launcher: 12, folder: runs/x}, epsilon_override: -1, gamma: 0.9}"));
  EXPECT_SAYS(controllerError("run: {idd: a}"), "unknown key run/idd");
  EXPECT_SAYS(controllerError("alpha_override: 0.1"), "unknown key alpha_override");
}

TEST(ControllerSettings, RefusesRelativeTablePathsThatLeaveTheirFolder)
{
  EXPECT_SAYS(controllerError("q_table_dir: ''"), "q_table_dir = '' is not allowed (must name a directory)");
  const std::string path = controllerError("{q_table_dir: /tmp/t, q_table_path: ../q.yaml}");
  EXPECT_SAYS(path, "qlearning_controller: q_table_path = '../q.yaml' is not allowed (");
  EXPECT_EQ("", controllerError("{q_table_dir: /tmp/t, q_table_path: /tmp/t/sub/q.yaml}"));
}

TEST(ControllerSettings, AnAbsoluteTablePathIsTheUsersOwn)
{
  // A parameter is set by the user (a launch argument): an absolute table lies where they say.
  // The services stay confined to the folder (RunApplicationTest.ServicesTakePathsUnderTheTableFolderOnly).
  const ControllerSettings s = readController("{q_table_dir: /tmp/t, q_table_path: /elsewhere/q.yaml}");
  EXPECT_EQ("/elsewhere/q.yaml", s.run.q_table_path);
  EXPECT_TRUE(s.run.own_absolute_paths);
}

TEST(ControllerSettings, RefusesAStatsCsvOutsideItsFolder)
{
  EXPECT_SAYS(controllerError("{q_table_dir: /tmp/t, stats_csv: ../curve.csv}"),
              "stats_csv = '../curve.csv' is not allowed (");
  // An absolute path is the user's own; "none" writes nothing.
  EXPECT_EQ("/data/curve.csv", readController("{q_table_dir: /tmp/t, stats_csv: /data/curve.csv}").run.stats_csv);
  EXPECT_EQ("none", readController("stats_csv: none").run.stats_csv);
}

TEST(ControllerSettings, ExpandsHomeInItsPaths)
{
  const ControllerSettings s = readController(
      "{q_table_dir: ~/tables, q_table_path: ~/tables/q.yaml, load_on_start: ~/tables/old.yaml, "
      "stats_csv: ~/tables/curve.csv}");
  EXPECT_EQ("/home/user/tables", s.run.q_table_dir);
  EXPECT_EQ("/home/user/tables/q.yaml", s.run.q_table_path);
  EXPECT_EQ("/home/user/tables/old.yaml", s.run.load_on_start);
  EXPECT_EQ("/home/user/tables/curve.csv", s.run.stats_csv);
  EXPECT_EQ("/home/user", readController("q_table_dir: '~'").run.q_table_dir);
  // "~name" is not looked up: a folder of that name under the working directory.
  EXPECT_EQ("~other/t", readController("q_table_dir: ~other/t").run.q_table_dir);

  ControllerContext homeless = context();
  homeless.home = "";
  EXPECT_SAYS(controllerError("q_table_dir: ~/tables", "", homeless), "q_table_dir = '~/tables' is not allowed (");
  EXPECT_SAYS(controllerError("load_on_start: ~/old.yaml", "", homeless),
              "load_on_start = '~/old.yaml' is not allowed (");
}

TEST(ControllerSettings, TheTableFolderIsTheNamespacesByDefault)
{
  ControllerContext other = context();
  other.name_space = "/left";
  const ControllerSettings s = readController("", "", other);
  EXPECT_EQ(defaultTableDirectory("/left"), s.run.q_table_dir);
  EXPECT_EQ("/left", s.run.name_space);
  EXPECT_NE(defaultTableDirectory("/cartpole"), s.run.q_table_dir);
}

TEST(ControllerSettings, RobotsAsACountAreNamedAsTrainLaunchNamesThem)
{
  EXPECT_EQ(std::vector<std::string>{""}, readController("robots: 1").robots);
  EXPECT_EQ((std::vector<std::string>{"robot_0", "robot_1", "robot_2"}), readController("robots: 3").robots);
  EXPECT_EQ(1000u, readController("robots: 1000").robots.size());
  EXPECT_EQ("robot_999", readController("robots: 1000").robots.back());
  EXPECT_EQ(robotNamespaces(4), readController("robots: 4").robots);
  const char* allowed =
      "is not allowed (a whole number in [1, 1000] or a list of namespaces relative to the "
      "controller's)";
  EXPECT_SAYS(controllerError("robots: 0"), std::string("robots = 0 ") + allowed);
  EXPECT_SAYS(controllerError("robots: 1001"), std::string("robots = 1001 ") + allowed);
  EXPECT_SAYS(controllerError("robots: -2"), std::string("robots = -2 ") + allowed);
  EXPECT_SAYS(controllerError("robots: 2.5"), std::string("robots = '2.5' ") + allowed);
  EXPECT_SAYS(controllerError("robots: {a: 1}"), std::string("robots = a map ") + allowed);
}

TEST(ControllerSettings, RobotsAsAListAreCheckedNames)
{
  EXPECT_EQ((std::vector<std::string>{"left", "right/arm"}), readController("robots: [left, right/arm]").robots);
  EXPECT_EQ((std::vector<std::string>{"", "far"}), readController("robots: ['', far]").robots);
  EXPECT_SAYS(controllerError("robots: []"), "robots = [] is not allowed (a whole number in [1, 1000]");
  EXPECT_SAYS(controllerError("robots: [left, 9lives]"),
              "robots = [left, 9lives] is not allowed ('9lives' is not a valid ROS name: must start with a letter)");
  EXPECT_SAYS(controllerError("robots: [left, right, left]"),
              "robots = [left, right, left] is not allowed ('left' is listed twice)");
  EXPECT_SAYS(controllerError("robots: [left, [a]]"), "robots = a list of mixed values is not allowed (");
}

TEST(ControllerSettings, RefusesABadStartRegion)
{
  EXPECT_SAYS(controllerError("start_region: [1, 1, 0, 1]"),
              "start_region = [1, 1, 0, 1] is not allowed (must be 4 finite values > 0: |x|, |x_dot|, |theta|, "
              "|theta_dot| bounds)");
  EXPECT_SAYS(controllerError("start_region: [1, 1, 1]"),
              "start_region = [1, 1, 1] is not allowed (must list 4 values");
  // Its default follows the random starts' bound, which must then be > 0 too.
  EXPECT_EQ(CartPoleState::Constant(0.2),
            readController("", "physics: {start_state_bound: 0.2}").protocol.start_region);
  EXPECT_SAYS(controllerError("", "physics: {start_state_bound: 0}"), "start_region = [0, 0, 0, 0] is not allowed");
}

TEST(ControllerSettings, RefusesANonPositiveSimTimeout)
{
  EXPECT_SAYS(controllerError("sim_timeout: 0"), "sim_timeout = 0 is not allowed (must be in (0, 3600] seconds");
  EXPECT_SAYS(controllerError("sim_timeout: .inf"), "sim_timeout = inf is not allowed (must be in (0, 3600] seconds");
}

TEST(ControllerSettings, RefusesAValueOfTheWrongType)
{
  EXPECT_SAYS(controllerError("sync: maybe"), "sync = 'maybe' is not allowed (must be true or false)");
  EXPECT_SAYS(controllerError("seed: many"), "seed = 'many' is not allowed (must be a whole number)");
}

TEST(RobotNamespaces, OneRobotIsTheLearnersOwnNamespace)
{
  EXPECT_EQ(std::vector<std::string>{""}, robotNamespaces(1));
  EXPECT_EQ((std::vector<std::string>{"robot_0", "robot_1"}), robotNamespaces(2));
}

// cartpole_sim

TEST(SimSettings, DefaultsAreTheDocumentedOnes)
{
  const SimSettings s = readSim("");
  EXPECT_EQ(SimMode::Realtime, s.mode);
  EXPECT_EQ(0u, s.seed);
  EXPECT_EQ(0.5, s.command_timeout);
  EXPECT_EQ(0.5, s.lockstep_timeout);
  EXPECT_EQ(30.0, s.tf_rate);
  EXPECT_EQ(10.0, s.effort_limit);
  EXPECT_FALSE(s.publish_clock);
  EXPECT_TRUE(s.publish_tf);
  EXPECT_EQ(0.0, s.track_y);
  EXPECT_EQ("world", s.world_frame);
  // "": the engine's bodies, the equations' cart and pole (PhysicsEngine::cartBody, poleBody).
  EXPECT_EQ("", s.cart_frame);
  EXPECT_EQ("", s.pole_frame);
  EXPECT_EQ("equations", s.engine.name);
  EXPECT_EQ("cart_joint", s.pose.cart_joint);
  EXPECT_EQ("pole_joint", s.pose.pole_joint);
  EXPECT_FALSE(s.perturbations.any());
  EXPECT_EQ("", s.suite_case);
  EXPECT_EQ(0.05, s.start_state_bound);
  EXPECT_EQ(0.02, s.physics.tau);
}

TEST(SimSettings, ReadsValidParametersAndThePhysics)
{
  // node_parameters_fail.test's ok fixture, and the rest.
  const SimSettings s = readSim(
      "{mode: lockstep, effort_limit: 5.0, seed: 4, publish_clock: true, publish_tf: false, tf_rate: 10, "
      "track_y: -2, cart_frame: robot_1/cart, lockstep_timeout: 0.2}",
      "physics: {mass_pole: 0.2, tau: 0.01, integrator: rk4, force_mag: 20, start_state_bound: 0.1}");
  EXPECT_EQ(SimMode::Lockstep, s.mode);
  EXPECT_EQ(5.0, s.effort_limit);
  EXPECT_EQ(4u, s.seed);
  EXPECT_TRUE(s.publish_clock);
  EXPECT_FALSE(s.publish_tf);
  EXPECT_EQ(10.0, s.tf_rate);
  EXPECT_EQ(-2.0, s.track_y);
  EXPECT_EQ("robot_1/cart", s.cart_frame);
  EXPECT_EQ(0.2, s.lockstep_timeout);
  EXPECT_EQ(0.2, s.physics.mass_pole);
  EXPECT_EQ(0.01, s.physics.tau);
  EXPECT_EQ(Integrator::Rk4, s.physics.integrator);
  EXPECT_EQ(0.1, s.start_state_bound);
  // The effort limit defaults to the force magnitude.
  EXPECT_EQ(20.0, readSim("", "physics: {force_mag: 20}").effort_limit);
}

TEST(SimSettings, StartsAsTheSharedTaskStarts)
{
  // CartPole-v1's: every value uniform in +-physics/start_state_bound, as before there were kinds.
  const SimSettings v1 = readSim("", "physics: {start_state_bound: 0.1}");
  EXPECT_EQ(TaskKind::CartPoleV1, v1.task);
  EXPECT_EQ(CartPoleState::Constant(0.1), v1.start.spread);
  EXPECT_EQ(CartPoleState::Zero(), v1.start.centre);
  // A swing-up task's pole hangs: the simulation draws its starts (the first, an empty reset) there.
  for (const char* kind : {"swingup", "swingup_sparse"})
  {
    const SimSettings s = readSim(
        "", std::string("{physics: {tau: 0.01, integrator: rk4, rail_limit: 1.8}, task: {kind: ") + kind + "}}");
    EXPECT_EQ(1.8, s.physics.rail_limit);
    CartPoleSimulation simulation(s.physics, s.start_state_bound, 0);
    simulation.setStart(s.start);
    for (int i = 0; i < 20; ++i)
      EXPECT_LT(std::cos(simulation.resetRandom()[2]), -0.99) << kind;
  }
  EXPECT_SAYS(simError("", "task: {kind: swing_up}"), "task/kind = 'swing_up' is not allowed");
}

TEST(SimSettings, RefusesAnUnknownMode)
{
  EXPECT_SAYS(simError("mode: warp"), "cartpole_sim: mode = 'warp' is not allowed (allowed: realtime, lockstep)");
}

TEST(SimSettings, RefusesBadPhysics)
{
  EXPECT_SAYS(simError("", "physics: {mass_pole: -1.0}"), "physics/mass_pole = -1 is not allowed");
  EXPECT_SAYS(simError("", "physics: {tau: 0}"), "physics/tau = 0 is not allowed");
  EXPECT_SAYS(simError("", "physics: {integrator: verlet}"), "physics/integrator = 'verlet' is not allowed");
}

TEST(SimSettings, RefusesAnEffortLimitAboveTheForceMagnitude)
{
  EXPECT_SAYS(simError("effort_limit: 50.0"), "effort_limit = 50 is not allowed (must be <= physics/force_mag = 10)");
  EXPECT_SAYS(simError("effort_limit: 0"), "effort_limit = 0 is not allowed (must be finite and > 0)");
  EXPECT_EQ("", simError("effort_limit: 50.0", "physics: {force_mag: 50}"));
}

TEST(SimSettings, RefusesAMisspeltPrivateParameter)
{
  const std::string error = simError("lockstep_timout: 0.3");
  EXPECT_SAYS(error, "/cartpole/cartpole_sim: unknown key lockstep_timout (known keys: ");
  EXPECT_SAYS(error, "lockstep_timeout");
}

TEST(SimSettings, PublishesTheClockOnlyInLockstep)
{
  EXPECT_SAYS(simError("{mode: realtime, publish_clock: true}"),
              "publish_clock = true is not allowed (only in lockstep mode: in realtime the wall clock is the clock)");
  EXPECT_SAYS(simError("publish_clock: true"), "publish_clock = true is not allowed (only in lockstep mode");
  EXPECT_EQ("", simError("{mode: lockstep, publish_clock: true}"));
}

TEST(SimSettings, RefusesBadTimesRatesAndNoise)
{
  EXPECT_SAYS(simError("seed: -3"), "seed = -3 is not allowed (must be a whole number >= 0)");
  EXPECT_SAYS(simError("command_timeout: 0"), "command_timeout = 0 is not allowed (must be in (0, 60] seconds");
  EXPECT_SAYS(simError("command_timeout: 500"), "command_timeout = 500 is not allowed (must be in (0, 60] seconds");
  EXPECT_SAYS(simError("lockstep_timeout: -1"), "lockstep_timeout = -1 is not allowed (must be in (0, 3600] seconds");
  EXPECT_SAYS(simError("tf_rate: 0"), "tf_rate = 0 is not allowed (must be finite and > 0)");
}

TEST(SimSettings, ReadsThePerturbationsAsTrainHeadlessReadsThem)
{
  const std::string shared =
      "{physics: {cart_friction: 0.0005, pole_friction: 0.000002}, perturbations: {delay_steps: [1, 2], "
      "noise_std: [0.01, 0, 0.0087, 0], noise_fraction: [0, 0.05, 0, 0.05], motor: [0.8, 0.9], "
      "push_probability: 0.2, push_force: 2.0}}";
  const SimSettings s = readSim("", shared);
  const TrainingConfig config = readTrainingConfig(*parseYamlParameters(shared, "config.yaml"));
  EXPECT_EQ(1u, s.perturbations.delay_steps);
  EXPECT_EQ(2u, s.perturbations.delay_steps_max);
  EXPECT_EQ(config.perturbations.noise_std, s.perturbations.noise_std);
  EXPECT_EQ(config.perturbations.noise_fraction, s.perturbations.noise_fraction);
  EXPECT_EQ(0.8, s.perturbations.motor.low);
  EXPECT_EQ(0.9, s.perturbations.motor.high);
  EXPECT_EQ(0.2, s.perturbations.push_probability);
  EXPECT_EQ(2.0, s.perturbations.push_force);
  EXPECT_EQ(0.0005, s.physics.cart_friction);
  EXPECT_EQ(0.000002, s.physics.pole_friction);
  EXPECT_SAYS(simError("", "perturbations: {delay_steps: -1}"), "perturbations/delay_steps = -1 is not allowed");
  EXPECT_SAYS(simError("", "perturbations: {noise: 1}"), "unknown key perturbations/noise");
}

TEST(SimSettings, RefusesTheFormerNoiseKeysNamingTheirReplacement)
{
  EXPECT_SAYS(simError("position_noise_std: 0.01"),
              "position_noise_std = 0.01 is not allowed (replaced by the shared perturbations section, as in "
              "config/cartpole.yaml: perturbations/noise_std");
  // Even a zero: the key would do nothing, silently.
  EXPECT_SAYS(simError("velocity_noise_std: 0"), "perturbations/noise_std and noise_fraction");
  EXPECT_SAYS(simError("effort_noise_std: 0.5"), "perturbations/motor: [low, high]");
}

TEST(SimSettings, PosesAsACaseOfTheSuite)
{
  const std::string suite = std::string(CARTPOLE_CONFIG_DIR) + "/robust_suite.yaml";
  // The case's perturbations replace the shared ones; its seed is the suite's unless ~seed is set.
  const SimSettings late = readSim("{suite: " + suite + ", suite_case: one_step_late}",
                                   "{physics: {tau: 0.01}, perturbations: {push_probability: 0.5, push_force: 1}}");
  EXPECT_EQ(1u, late.perturbations.delay_steps);
  EXPECT_EQ(0.0, late.perturbations.push_probability);
  EXPECT_EQ(0.01, late.physics.tau);
  EXPECT_EQ(0.05, late.start_state_bound);
  EXPECT_EQ(1000u, late.seed);
  EXPECT_EQ("one_step_late", late.suite_case);
  EXPECT_EQ(7u, readSim("{suite: " + suite + ", suite_case: wide_starts, seed: 7}").seed);
  EXPECT_EQ(0.1, readSim("{suite: " + suite + ", suite_case: wide_starts}").start_state_bound);
  // A suite without a case changes nothing.
  EXPECT_FALSE(readSim("suite: " + suite).perturbations.any());
  EXPECT_SAYS(simError("{suite: " + suite + ", suite_case: late}"),
              "suite_case = 'late' is not allowed (the cases of " + suite + ": nominal, one_step_late, sensor_noise");
  EXPECT_SAYS(simError("suite_case: nominal"), "suite_case = 'nominal' is not allowed (needs ~suite");
  EXPECT_SAYS(simError("{suite: /nonexistent.yaml, suite_case: nominal}"), "/nonexistent.yaml: cannot be read");
}

// A MuJoCo model's physics (config/mujoco_cartpole.yaml's, as the launch files load it): the sim
// steps it, and the sim and the controller name the joints as the model does.
const char* const kModelPhysics =
    "physics: {engine: mujoco, model: ../mjcf/model.xml, cart_joint: rail, pole_joint: swing, actuator: motor}";

TEST(SimSettings, ReadsAMujocoModelRelativeToTheConfigsFolderAndPublishesItsJointNames)
{
  const SimSettings s = readSimSettings(*parseYamlParameters(kModelPhysics, "/cartpole", "/home/me/config"),
                                        *parseYamlParameters("", kSim));
  EXPECT_EQ("mujoco", s.engine.name);
  EXPECT_EQ("/home/me/config/../mjcf/model.xml", s.engine.model);
  EXPECT_EQ("motor", s.engine.actuator);
  EXPECT_EQ("rail", s.pose.cart_joint);
  EXPECT_EQ("swing", s.pose.pole_joint);
  // ~cart_joint and ~pole_joint still rename them (posing as another robot).
  const SimSettings posed = readSim("{cart_joint: slider_to_cart, pole_joint: cart_to_pole}", kModelPhysics);
  EXPECT_EQ("slider_to_cart", posed.pose.cart_joint);
  EXPECT_EQ("cart_to_pole", posed.pose.pole_joint);
  // The model's keys beside the equations, and the equations' beside a model, are refused as in train_headless.
  EXPECT_SAYS(simError("", "physics: {engine: mujoco, model: m.xml, gravity: 9.8}"),
              "physics/gravity is not allowed with physics/engine mujoco");
  EXPECT_SAYS(simError("", "perturbations: {half_length: [0.9, 1.1]}\n" + std::string(kModelPhysics)),
              "perturbations/half_length is not allowed with physics/engine mujoco");
}

TEST(SimSettings, PosesAsAMujocoCaseOfTheSimToSimSuite)
{
  const std::string suite = std::string(CARTPOLE_CONFIG_DIR) + "/sim_to_sim_suite.yaml";
  const SimSettings s = readSim("{suite: " + suite + ", suite_case: mujoco}");
  EXPECT_EQ("mujoco", s.engine.name);
  EXPECT_EQ(std::string(CARTPOLE_CONFIG_DIR) + "/../mjcf/cartpole.xml", s.engine.model);
  EXPECT_EQ("cart_joint", s.pose.cart_joint);
  EXPECT_EQ(1000u, s.seed);
}

TEST(ControllerSettings, FindsAMujocoModelsJointsByTheirNames)
{
  const ControllerSettings s = readController("", kModelPhysics);
  EXPECT_EQ("rail", s.robot.cart_joint);
  EXPECT_EQ("swing", s.robot.pole_joint);
  EXPECT_EQ("rail", s.robot.command_joint);
  // A robot's own names still win (robot.launch cart_joint:=...).
  EXPECT_EQ("slider_to_cart", readController("cart_joint: slider_to_cart", kModelPhysics).robot.cart_joint);
  // The equations' robot keeps the URDF's names.
  EXPECT_EQ("cart_joint", readController("").robot.cart_joint);
}

TEST(SimSettings, RefusesAnInfiniteTrackOrAnEmptyFrame)
{
  EXPECT_SAYS(simError("track_y: .inf"), "track_y = inf is not allowed (must be finite)");
  EXPECT_SAYS(simError("pole_frame: ''"), "pole_frame = '' is not allowed (frame names must not be empty)");
  EXPECT_SAYS(simError("world_frame: ''"), "world_frame = '' is not allowed (frame names must not be empty)");
}

TEST(ControllerSettings, AnEvaluationOfASuiteCaseSaysTheCaseAndItsPassCount)
{
  const std::string suite = std::string(CARTPOLE_CONFIG_DIR) + "/robust_suite.yaml";
  const ControllerSettings s = readController("{mode: evaluate, suite: " + suite + ", suite_case: all_at_once}");
  EXPECT_EQ("case all_at_once of " + suite, s.run.evaluation_case);
  // The suite's episodes unless evaluation_episodes is set, the pass count scaled to them.
  EXPECT_EQ(100u, s.run.evaluation_episodes);
  EXPECT_EQ(95u, s.run.evaluation_pass);
  const ControllerSettings shorter =
      readController("{mode: evaluate, evaluation_episodes: 20, suite: " + suite + ", suite_case: pushes}");
  EXPECT_EQ(20u, shorter.run.evaluation_episodes);
  EXPECT_EQ(20u, shorter.run.evaluation_pass);  // 98 of 100: 19.6 of 20, rounded up
  EXPECT_EQ("", readController("{mode: evaluate, suite: " + suite + "}").run.evaluation_case);
  EXPECT_SAYS(controllerError("{mode: train, suite: " + suite + ", suite_case: nominal}"),
              "suite_case = 'nominal' is not allowed (only with mode evaluate");
  EXPECT_SAYS(controllerError("{mode: evaluate, suite: " + suite + ", suite_case: heavy}"),
              "suite_case = 'heavy' is not allowed (the cases of " + suite + ": nominal");
}

TEST(ControllerSettings, ReadsAnotherRobotsJointsOffsetsAndCommand)
{
  const ControllerSettings d = readController("");
  EXPECT_EQ("cart_joint", d.robot.cart_joint);
  EXPECT_EQ("pole_joint", d.robot.pole_joint);
  EXPECT_EQ("cart_joint", d.robot.command_joint);
  EXPECT_EQ("joint_states", d.robot.state_topic);
  EXPECT_EQ("joint_command", d.robot.command_topic);
  EXPECT_EQ(CommandType::JointState, d.robot.command_type);
  EXPECT_EQ(0.02, d.robot.decision_period);  // physics/tau
  EXPECT_EQ("cartpole_qlearning/Reset", d.reset_service_type);
  EXPECT_EQ(0.04, readController("", "physics: {tau: 0.04}").robot.decision_period);
  const ControllerSettings s = readController(
      "{cart_joint: slider_to_cart, pole_joint: cart_to_pole, pole_upright: -0.25, pole_angle_sign: -1, "
      "cart_sign: -1, cart_zero: 0.5, command_type: float64_array, command_index: 1, command_size: 2, "
      "effort_sign: -1, decision_period: 0, velocity_smoothing: 0.3, reset_service_type: std_srvs/Empty}");
  EXPECT_EQ("slider_to_cart", s.robot.cart_joint);
  EXPECT_EQ("cart_to_pole", s.robot.pole_joint);
  EXPECT_EQ("slider_to_cart", s.robot.command_joint);
  EXPECT_EQ(-0.25, s.robot.pole_upright);
  EXPECT_EQ(-1.0, s.robot.pole_angle_sign);
  EXPECT_EQ(-1.0, s.robot.cart_sign);
  EXPECT_EQ(0.5, s.robot.cart_zero);
  EXPECT_EQ(CommandType::Float64Array, s.robot.command_type);
  EXPECT_EQ(1u, s.robot.command_index);
  EXPECT_EQ(2u, s.robot.command_size);
  EXPECT_EQ(-1.0, s.robot.effort_sign);
  EXPECT_EQ(0.0, s.robot.decision_period);
  EXPECT_EQ(0.3, s.robot.velocity_smoothing);
  EXPECT_EQ("std_srvs/Empty", s.reset_service_type);
  EXPECT_TRUE(s.protocol.reset_starts_in_region);
  EXPECT_FALSE(d.protocol.reset_starts_in_region);
}

TEST(ControllerSettings, RefusesABadRobotInterface)
{
  EXPECT_SAYS(controllerError("pole_angle_sign: 2"), "pole_angle_sign = 2 is not allowed (must be 1 or -1)");
  EXPECT_SAYS(controllerError("command_type: twist"), "command_type = 'twist' is not allowed");
  EXPECT_SAYS(controllerError("{command_index: 2, command_size: 2}"), "command_index = 2 is not allowed");
  EXPECT_SAYS(controllerError("pole_joint: cart_joint"), "pole_joint = 'cart_joint' is not allowed");
  EXPECT_SAYS(controllerError("state_topic: ''"), "state_topic = '' is not allowed (must not be empty)");
  EXPECT_SAYS(controllerError("decision_period: -0.1"), "decision_period = -0.1 is not allowed");
  // Milliseconds typed as seconds: one decision, then its effort held until the pole fell.
  EXPECT_SAYS(controllerError("decision_period: 20"),
              "decision_period = 20 is not allowed (must be in [0, 1] seconds (20 ms is 0.02))");
  EXPECT_SAYS(controllerError("decision_period: 1e9"), "decision_period = 1e+09 is not allowed");
  EXPECT_SAYS(controllerError("velocity_smoothing: 1"), "velocity_smoothing = 1 is not allowed");
  EXPECT_SAYS(controllerError("reset_service_type: std_srvs/SetBool"), "reset_service_type = 'std_srvs/SetBool'");
}

TEST(SimSettings, PosesAsAnotherCartPole)
{
  const SimSettings d = readSim("");
  EXPECT_EQ("cart_joint", d.pose.cart_joint);
  EXPECT_EQ(0, d.pole_turns);
  EXPECT_TRUE(d.publish_velocities);
  const SimSettings s = readSim(
      "{cart_joint: slider_to_cart, pole_joint: cart_to_pole, pole_upright: -0.25, pole_angle_sign: -1, "
      "pole_turns: 2, publish_velocities: false}");
  EXPECT_EQ("slider_to_cart", s.pose.cart_joint);
  EXPECT_EQ("cart_to_pole", s.pose.pole_joint);
  EXPECT_EQ(-0.25, s.pose.pole_upright);
  EXPECT_EQ(-1.0, s.pose.pole_angle_sign);
  EXPECT_EQ(2, s.pole_turns);
  EXPECT_FALSE(s.publish_velocities);
  EXPECT_SAYS(simError("cart_sign: 0"), "cart_sign = 0 is not allowed (must be 1 or -1)");
  // The pose is read as the controller reads a robot's (readRobotPose): one joint cannot be both.
  EXPECT_SAYS(simError("pole_joint: cart_joint"),
              "pole_joint = 'cart_joint' is not allowed (must differ from ~cart_joint)");
}

TEST(SimSettings, PosesAtAnotherStateRateAndEffortSign)
{
  const SimSettings d = readSim("", "physics: {tau: 0.01}");
  EXPECT_EQ(0.01, d.publish_period);  // physics/tau
  EXPECT_EQ(1.0, d.pose.effort_sign);
  const SimSettings s = readSim("{publish_period: 0.0333333333, effort_sign: -1}");
  EXPECT_EQ(0.0333333333, s.publish_period);
  EXPECT_EQ(0.02, s.physics.tau);
  EXPECT_EQ(-1.0, s.pose.effort_sign);
  EXPECT_SAYS(simError("publish_period: 0"), "publish_period = 0 is not allowed (must be in [1e-06, 1] s)");
  EXPECT_SAYS(simError("publish_period: 2"), "publish_period = 2 is not allowed (must be in [1e-06, 1] s)");
  EXPECT_SAYS(simError("publish_period: .nan"), "publish_period = nan is not allowed");
  EXPECT_SAYS(simError("effort_sign: 2"), "effort_sign = 2 is not allowed (must be 1 or -1)");
  EXPECT_EQ(0u, d.group_effort_index);
  EXPECT_EQ(2u, readSim("group_effort_index: 2").group_effort_index);
  EXPECT_SAYS(simError("group_effort_index: -1"),
              "group_effort_index = -1 is not allowed (must be a whole number >= 0)");
}

TEST(ControllerSettings, TheStartLineSaysWhatTheControllerDoes)
{
  const ControllerSettings s = readController("");
  const QTable table(s.training.agent.featureParams(), s.training.agent.actions);
  EXPECT_EQ(
      "training, seed 0, 72 states x 2 actions, tables under /t; serving /cartpole/joint_states; resets by "
      "~cartpole_sim/reset",
      controllerStartText(s, table, "/t", "/cartpole/joint_states"));
  const ControllerSettings e = readController("{mode: evaluate, seed: 3, robots: 2, sync: false, reset_service: ''}");
  EXPECT_EQ(
      "evaluating (greedy, no learning) in episodes of 500 steps with /cartpole, seed 3, 72 states x 2 actions, "
      "tables under /t; serving a, b, each as "
      "its states come; finding how many steps late the robot carries out its commands from how its states answer "
      "them, then deciding for the state predicted that far ahead (~predict_delay_steps N tells it instead); no "
      "reset service: an episode starts when the pole is up (inside the task's thresholds), "
      "the next at once after a step limit, and after a fall the pole stays down until someone stands it up (the "
      "robot's own count of episodes, if it keeps one, may differ)",
      controllerStartText(e, table, "/t", "a, b"));
  const ControllerSettings t = readController("{reset_service: ''}");
  EXPECT_NE(std::string::npos, controllerStartText(t, table, "/t", "a")
                                   .find("no reset service: episodes start when the state is in ~start_region"));
  EXPECT_FALSE(t.protocol.starts_when_up);
  EXPECT_TRUE(e.protocol.starts_when_up);
}

namespace
{
// A folder of tables for the controller's ~q_table_dir, removed at the end.
struct TableFolder
{
  TableFolder() : path("/tmp/node_settings_test_" + std::to_string(::getpid()))
  {
    std::filesystem::create_directories(path);
  }
  ~TableFolder()
  {
    std::filesystem::remove_all(path);
  }
  std::string path;
};
TEST(DefaultTableDirectory, EachNamespaceHasAFolderOfItsOwnUnderRosHome)
{
  // What train.launch ns:=NAME relies on: two namespaces never share (or write) each other's tables.
  const char* before = std::getenv("ROS_HOME");
  const std::string saved = before != nullptr ? before : "";
  ::setenv("ROS_HOME", "/somewhere/ros_home", 1);
  EXPECT_EQ("/somewhere/ros_home/cartpole_qlearning/cartpole", defaultTableDirectory("/cartpole"));
  EXPECT_EQ("/somewhere/ros_home/cartpole_qlearning/first", defaultTableDirectory("/first"));
  EXPECT_EQ("/somewhere/ros_home/cartpole_qlearning/second", defaultTableDirectory("/second"));
  EXPECT_EQ("/somewhere/ros_home/cartpole_qlearning/fleet/robot_1", defaultTableDirectory("/fleet/robot_1"));
  EXPECT_EQ("/somewhere/ros_home/cartpole_qlearning", defaultTableDirectory("/"));
  ::unsetenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  EXPECT_EQ(std::string(home != nullptr ? home : ".") + "/.ros/cartpole_qlearning/first",
            defaultTableDirectory("/first"));
  if (before != nullptr)
    ::setenv("ROS_HOME", saved.c_str(), 1);
}

}  // namespace

TEST(ControllerSettings, AnEvaluationOfATableAloneRunsWithTheTablesOwnConfiguration)
{
  const TableFolder folder;
  const TrainingConfig trained = readTrainingConfig(
      *parseYamlParameters("{physics: {tau: 0.01}, task: {max_episode_steps: 200, x_threshold: 1.5}, "
                           "learning: {bins: [3, 3, 6, 12], actions: [-5, 0, 5]}}",
                           "robust.yaml"));
  QTable table(trained.agent.featureParams(), trained.agent.actions);
  table.tau = trained.physics.tau;
  table.trained_with = trainingConfigText(trained);
  saveQTableFile(table, folder.path + "/t.yaml");
  const std::string evaluate = "{mode: evaluate, load_on_start: t.yaml, q_table_dir: " + folder.path + "}";

  // No configuration beside it: the table's, its step deciding when to act.
  const ControllerSettings alone = readController(evaluate);
  EXPECT_EQ(trained.agent.discretiser.bins, alone.training.agent.discretiser.bins);
  EXPECT_EQ(trained.agent.actions, alone.training.agent.actions);
  EXPECT_EQ(1.5, alone.training.task.x_threshold);
  EXPECT_EQ(0.01, alone.robot.decision_period);
  EXPECT_EQ("the table's own configuration (" + folder.path + "/t.yaml)", alone.run.config_origin);
  EXPECT_EQ("", alone.run.config_warning);

  // A configuration beside it is the run's (RunApplication checks that it fits the table).
  const ControllerSettings given = readController(evaluate, "{learning: {gamma: 0.5}}");
  EXPECT_EQ(AgentParams().discretiser.bins, given.training.agent.discretiser.bins);
  EXPECT_EQ("/cartpole", given.run.config_origin);
  // Training takes the configuration, never the table's.
  EXPECT_EQ(AgentParams().discretiser.bins,
            readController("{mode: train, load_on_start: t.yaml, q_table_dir: " + folder.path + "}")
                .training.agent.discretiser.bins);

  // A table that cannot be read stops the node, naming the parameter.
  EXPECT_SAYS(controllerError("{mode: evaluate, load_on_start: none.yaml, q_table_dir: " + folder.path + "}"),
              "cannot start from the table 'none.yaml' (~load_on_start, which the launch files' q_table or load "
              "argument sets): ");
  // A table without its configuration: its features, the rest the defaults, and said so.
  saveQTableFile(QTable(trained.agent.featureParams(), trained.agent.actions), folder.path + "/v2.yaml");
  const ControllerSettings v2 =
      readController("{mode: evaluate, load_on_start: v2.yaml, q_table_dir: " + folder.path + "}");
  EXPECT_EQ(trained.agent.discretiser.bins, v2.training.agent.discretiser.bins);
  EXPECT_EQ(0.02, v2.training.physics.tau);
  EXPECT_NE(std::string::npos, v2.run.config_warning.find("does not say which configuration trained it"));
}

TEST(ControllerSettings, AnEvaluationsEpisodesAreItsOwnLengthNeverTheTrainings)
{
  // The training configuration's 200 steps are training's episodes.
  const std::string shared = "{task: {max_episode_steps: 200}}";
  EXPECT_EQ(200u, readController("", shared).training.task.max_episode_steps);
  EXPECT_EQ(kEvaluationMaxSteps, readController("mode: evaluate", shared).training.task.max_episode_steps);
  EXPECT_EQ(3000u, readController("{mode: evaluate, max_steps: 3000}", shared).training.task.max_episode_steps);
  // Posing as a suite case: the suite's.
  const std::string suite = std::string(CARTPOLE_CONFIG_DIR) + "/robust_suite.yaml";
  const ControllerSettings posed =
      readController("{mode: evaluate, suite: " + suite + ", suite_case: nominal}", shared);
  EXPECT_EQ(loadRobustnessSuite(suite, TrainingConfig()).max_episode_steps, posed.training.task.max_episode_steps);
  EXPECT_EQ(60u, readController("{mode: evaluate, suite: " + suite + ", suite_case: nominal, max_steps: 60}", shared)
                     .training.task.max_episode_steps);
  EXPECT_SAYS(controllerError("max_steps: 3000"),
              "max_steps = 3000 is not allowed (only with mode evaluate: training's episodes are "
              "task/max_episode_steps long)");
  EXPECT_SAYS(controllerError("{mode: evaluate, max_steps: 0}"), "max_steps = 0 is not allowed");
}
