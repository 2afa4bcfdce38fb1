#include "cartpole_qlearning/node_settings/controller_settings.h"

#include "settings_parts.h"

#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/learning/table_config.h"
#include "cartpole_qlearning/node_settings/node_setting_names.h"
#include "cartpole_qlearning/node_settings/robot_settings.h"
#include "cartpole_qlearning/node_settings/table_folder.h"
#include "cartpole_qlearning/protocol/reset_calls.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
constexpr std::int64_t kMaxRobots = 1000;

bool endsWith(const std::string& text, const std::string& end)
{
  return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

std::string listText(const std::vector<std::string>& names)
{
  std::string text;
  for (const std::string& name : names)
    text += (text.empty() ? "" : ", ") + name;
  return "[" + text + "]";
}

// ~robots: a list of namespaces (relative to the learner's), or a whole number N: one robot,
// the learner's own namespace (N = 1), or robot_0 ... robot_<N-1> (train.launch robots:=N).
void readRobots(const ParameterSource& source, SectionReader& priv, const ControllerContext& context,
                std::vector<std::string>& robots)
{
  priv.know("robots");
  const std::string allowed =
      "a whole number in [1, " + std::to_string(kMaxRobots) + "] or a list of namespaces relative to the controller's";
  std::int64_t count = 0;
  bool whole_number = false;
  try
  {
    if (!source.get("robots", count))
      return;
    whole_number = true;
  }
  catch (const ConfigError&)  // not a whole number: a list, or nothing allowed
  {
  }
  if (whole_number)
  {
    if (count < 1 || count > kMaxRobots)
      priv.fail("robots", std::to_string(count), allowed);
    robots = robotNamespaces(static_cast<std::size_t>(count));
    return;
  }
  std::vector<std::string> names;
  try
  {
    source.get("robots", names);
  }
  catch (const ConfigError&)
  {
    priv.fail("robots", anyValueText(source, "robots"), allowed);
  }
  if (names.empty() || names.size() > static_cast<std::size_t>(kMaxRobots))
    priv.fail("robots", listText(names), allowed);
  for (auto it = names.begin(); it != names.end(); ++it)
  {
    const std::string error = it->empty() || !context.name_error ? "" : context.name_error(*it);
    if (!error.empty())
      priv.fail("robots", listText(names), "'" + *it + "' is not a valid ROS name: " + error);
    if (std::find(names.begin(), it, *it) != it)
      priv.fail("robots", listText(names), "'" + *it + "' is listed twice");
  }
  robots = std::move(names);
}

// The robot's joints, offsets and command (robot_interface.h; docs/your_own_cartpole.md).
void readRobotInterface(SectionReader& priv, double tau, RobotInterfaceParams& robot)
{
  readRobotPose(priv, robot);
  for (const auto& [name, topic] : {std::pair<const char*, std::string*>{"state_topic", &robot.state_topic},
                                    {"command_topic", &robot.command_topic}})
  {
    priv.read(name, *topic);
    if (topic->empty())
      priv.fail(name, "''", "must not be empty");
  }
  priv.read("velocity_smoothing", robot.velocity_smoothing);
  if (!(robot.velocity_smoothing >= 0.0 && robot.velocity_smoothing < 1.0))
    priv.fail("velocity_smoothing", SectionReader::numberText(robot.velocity_smoothing), "must be in [0, 1)");
  readRobotCommand(priv, robot);
  priv.read("max_effort", robot.max_effort);
  if (!(robot.max_effort > 0.0))
    priv.fail("max_effort", SectionReader::numberText(robot.max_effort),
              "must be > 0 N: the most effort the robot may be commanded (absent: no limit)");
  robot.decision_period = tau;
  // Over a second the pole has fallen between two decisions.
  priv.readSeconds("decision_period", robot.decision_period, 0.0, 1.0, false);
}

// What a table driving a robot (evaluate, control) is allowed but its owner should hear once:
// values far from the step the table learnt, and commands no limit bounds.
std::vector<std::string> drivingWarnings(const ControllerSettings& settings)
{
  std::vector<std::string> warnings;
  const double tau = settings.training.physics.tau;
  const std::string step = "the table's step (physics/tau) of " + SectionReader::numberText(tau) + " s";
  const auto times = [tau](double value) { return SectionReader::numberText(std::round(value / tau * 10.0) / 10.0); };
  const double period = settings.robot.decision_period;
  if (period > 0.0 && (period > 1.5 * tau || period < tau / 1.5))
    warnings.push_back("~decision_period = " + SectionReader::numberText(period) + " s is " + times(period) +
                       " times " + step + ": the table decides as if " + SectionReader::numberText(tau) +
                       " s passed between its decisions");
  const double freshness = settings.freshness_timeout;
  if (freshness > 0.5 && freshness > 25.0 * tau)
    warnings.push_back("~freshness_timeout = " + SectionReader::numberText(freshness) + " s is " + times(freshness) +
                       " times " + step + ": when fresh states stop, the last command goes on pushing the robot " +
                       "that long before 0");
  const unsigned delay = settings.run.predict_delay_steps;
  if (delay > 5 && delay != kDelayFoundFromStates)
    warnings.push_back("~predict_delay_steps = " + std::to_string(delay) + " predicts " +
                       SectionReader::numberText(delay * tau) + " s ahead at " + step +
                       ": a robot that late is rare; the prediction drifts from the robot the further it looks");
  if (settings.run.controlling() && !std::isfinite(settings.robot.max_effort))
  {
    double largest = 0.0;
    for (const double action : settings.training.agent.actions)
      largest = std::max(largest, std::abs(action));
    warnings.push_back("no ~max_effort: commands go out as the table's actions, up to " +
                       SectionReader::numberText(largest) +
                       " N; give the robot's limit (robot.launch max_effort:=N) to bound every command");
  }
  return warnings;
}

// An evaluation of a table with no configuration beside it: the table's own (table_config.h).
void useTablesOwnConfig(RunSettings& run, TrainingConfig& training)
{
  const TableStore tables(run.q_table_dir, run.q_table_path,
                          run.own_absolute_paths ? AbsolutePaths::AreTheUsersFiles : AbsolutePaths::MustLieInTheFolder);
  std::string path = run.load_on_start;
  TableConfig own;
  try
  {
    path = tables.resolve(run.load_on_start);
    own = tableConfig(tables.load(run.load_on_start), path);
  }
  catch (const FileError& e)
  {
    // As RunApplication::start says it for a table that cannot be used.
    throw ConfigError("cannot start from the table '" + run.load_on_start + "' (" +
                      run.names(Setting::LoadOnStartOrigin) + "): " + e.what());
  }
  training = own.config;
  run.config_origin = "the table's own configuration (" + path + ")";
  run.config_warning = own.defaults_used;
}

// A relative path under the table folder that does not leave it, else a refusal of `name`.
void checkUnderTableFolder(SectionReader& priv, const std::string& name, const RunSettings& run,
                           const std::string& path)
{
  try
  {
    relativePathUnder(run.q_table_dir, path);
  }
  catch (const FileError& e)
  {
    priv.fail(name, "'" + path + "'", e.what());
  }
}

// ~q_table_dir, ~q_table_path, ~load_on_start and ~stats_csv, "~/" expanded; an evaluation of a
// table with no configuration in `shared` takes the table's own.
void readTablePaths(const ParameterSource& shared, SectionReader& priv, const ControllerContext& context,
                    ControllerSettings& settings)
{
  RunSettings& run = settings.run;
  run.q_table_dir = defaultTableDirectory(context.name_space);
  priv.read("q_table_dir", run.q_table_dir);
  if (run.q_table_dir.empty())
    priv.fail("q_table_dir", "''", "must name a directory");
  // Paths given as "~/..." (roslaunch passes them on unexpanded) name the user's home.
  const auto expand_home = [&](const std::string& name, std::string& path) {
    try
    {
      path = expandHome(path, context.home);
    }
    catch (const FileError& e)
    {
      priv.fail(name, "'" + path + "'", e.what());
    }
  };
  const auto read_path = [&](const std::string& name, std::string& path) {
    priv.read(name, path);
    expand_home(name, path);
  };
  expand_home("q_table_dir", run.q_table_dir);
  std::string config_file;  // the launch's config (train.launch config:=), named in the namespace
  shared.get("config_file", config_file);
  run.q_table_path = defaultTableName(config_file);
  read_path("q_table_path", run.q_table_path);
  // The node's parameters are the user's, as the launch arguments that set them: an absolute
  // ~q_table_path or ~load_on_start is followed as given. Only a service's path (its caller is
  // anyone on the graph) must stay inside ~q_table_dir (TableStore::resolveForService).
  run.own_absolute_paths = true;
  if (run.q_table_path.empty() || run.q_table_path.front() != '/')
    checkUnderTableFolder(priv, "q_table_path", run, run.q_table_path);
  read_path("load_on_start", run.load_on_start);
  if (!run.learning() && !run.load_on_start.empty() && !holdsTrainingConfig(shared))
    useTablesOwnConfig(run, settings.training);
  // The launch files' stop_when_solved and max_episodes arrive as private parameters; they
  // override the shared training/ keys for this controller only.
  priv.read("stop_when_solved", settings.training.limits.stop_when_solved);
  priv.read("max_episodes", settings.training.limits.max_episodes, 1);
  read_path("stats_csv", run.stats_csv);
  if (run.stats_csv != "none" && !run.stats_csv.empty() && run.stats_csv.front() != '/')
    checkUnderTableFolder(priv, "stats_csv", run, run.stats_csv);
}

// ~evaluation_episodes, ~suite and ~suite_case, ~max_steps, ~report_every and
// ~predict_delay_steps: how an evaluation or control runs. Returns the engine whose joints the
// robot has by default (a suite case's, else the training's).
EngineParams readEvaluation(const ParameterSource& source, SectionReader& priv, ControllerSettings& settings)
{
  RunSettings& run = settings.run;
  priv.read("evaluation_episodes", run.evaluation_episodes, 0);
  // What the sim poses as (evaluate.launch suite_case:=NAME), for the verdict to say.
  unsigned max_steps = kEvaluationMaxSteps;
  EngineParams robot_engine = settings.training.engine;
  if (const auto found = readSuiteCase(priv, settings.training))
  {
    const auto& [suite, suite_case] = *found;
    robot_engine = suite_case.engine;
    max_steps = suite.max_episode_steps;
    if (run.learning())
      priv.fail("suite_case", "'" + suite_case.name + "'", "only with mode evaluate: the verdict says the case");
    if (source.keysUnder("evaluation_episodes").empty())
      run.evaluation_episodes = suite.episodes;
    run.evaluation_case = "case " + suite_case.name + " of " + suite.origin;
    // The case's pass count, for as many episodes as the verdict comes after (rounded up).
    run.evaluation_pass = (suite_case.pass * run.evaluation_episodes + suite.episodes - 1) / suite.episodes;
  }
  priv.read("max_steps", max_steps, 1, std::numeric_limits<int>::max());
  if (run.mode != RunMode::Evaluate && !source.keysUnder("max_steps").empty())
    priv.fail("max_steps", std::to_string(max_steps),
              run.controlling() ? "not with mode control, which has no step limit: only with mode evaluate"
                                : "only with mode evaluate: training's episodes are task/max_episode_steps long");
  // The Control Suite's tasks are scored over their own 1,000 steps unless told otherwise.
  if (!run.learning() && (!isSuiteTask(settings.training.task.kind) || !source.keysUnder("max_steps").empty()))
    settings.training.task.max_episode_steps = max_steps;
  if (run.controlling())
  {
    // No step limit (a stretch ends only with a fall; 2^32 - 1 steps are 2.7 years at 50 Hz) and no verdict.
    settings.training.task.max_episode_steps = std::numeric_limits<unsigned>::max();
    run.evaluation_episodes = 0;
    if (!run.evaluation_case.empty())
      priv.fail("suite_case", "'" + run.evaluation_case + "'", "only with mode evaluate: the verdict says the case");
    if (run.load_on_start.empty())
      priv.fail("mode", "control", "needs ~load_on_start: a trained table to drive the robot with");
  }
  priv.readSeconds("report_every", run.report_every, 0.0, 3600.0, true);
  if (!run.controlling() && !source.keysUnder("report_every").empty())
    priv.fail("report_every", SectionReader::numberText(run.report_every), "only with mode control");
  // A robot known to answer late: decide for the state the table's model predicts for when the command acts.
  // Not told: found from the robot's states when greedy (readRobotSide).
  priv.read("predict_delay_steps", run.predict_delay_steps, 0, kMaxPredictedDelaySteps);
  if (run.learning() && run.predict_delay_steps > 0)
    priv.fail("predict_delay_steps", std::to_string(run.predict_delay_steps),
              "only with mode evaluate or control: training learns from the states it observes");
  return robot_engine;
}

// ~freshness_timeout (and ~robot_lockstep, which turns the guard off by default), and the
// control's clock that follows from it.
void readFreshness(SectionReader& priv, ControllerSettings& settings)
{
  RunSettings& run = settings.run;
  // The freshness guard's bound: a few decision periods, and no less than 0.1 s (a real-time
  // machine's hiccup is not a robot gone). 0 turns it off: a lockstep sim holds no command.
  priv.read("robot_lockstep", settings.robot_lockstep);
  settings.freshness_timeout = settings.robot_lockstep ? 0.0 : std::max(0.1, 5.0 * settings.robot.decision_period);
  priv.readSeconds("freshness_timeout", settings.freshness_timeout, 0.0, 10.0, false);
  // A robot that holds its last command (every real one, a realtime sim) is pushed by it for as
  // long as nothing replaces it: without the guard a driver that stops or freezes keeps the last
  // push on. Only a sim that steps when answered holds nothing.
  if (run.controlling() && settings.freshness_timeout == 0.0 && !settings.robot_lockstep)
    priv.fail("freshness_timeout", "0",
              "mode control drives a robot that holds its last command: the guard that commands 0 when fresh "
              "states stop can be off only for a sim in lockstep (~robot_lockstep: true)");
  // Control's clock: a gap between two decisions counts at most this (beyond it the guard has
  // commanded 0, or, with the guard off, the robot was not being driven).
  run.control_max_gap =
      std::max({settings.freshness_timeout, 5.0 * settings.robot.decision_period, 5.0 * settings.training.physics.tau});
}

// The robot's side: its reset service, start region, joints, command and freshness guard, and
// whether a greedy table finds the robot's delay.
void readRobotSide(const ParameterSource& source, SectionReader& priv, const EngineParams& robot_engine,
                   ControllerSettings& settings)
{
  RunSettings& run = settings.run;
  priv.read("reset_service", settings.reset_service);
  ControllerProtocolParams& protocol = settings.protocol;
  protocol.reset_service = !settings.reset_service.empty();
  settings.simulated = endsWith(settings.reset_service, "cartpole_sim/reset") ||
                       endsWith(settings.reset_service, "cartpole_sim/reset_simulation");
  std::array<double, kStateDimensions> region{};
  region.fill(settings.training.start_state_bound);
  readDimensions(priv, "start_region", region, false);
  for (std::size_t i = 0; i < kStateDimensions; ++i)
  {
    if (!(std::isfinite(region[i]) && region[i] > 0.0))
      priv.fail("start_region", SectionReader::listText({region.begin(), region.end()}),
                "must be 4 finite values > 0: |x|, |x_dot|, |theta|, |theta_dot| bounds");
    protocol.start_region[i] = region[i];
  }
  useModelJoints(robot_engine, settings.robot);
  readRobotInterface(priv, settings.training.physics.tau, settings.robot);
  // The model predicts one decision at a time, each physics/tau long: on a robot decided on at
  // another period a step of its delay is not a step of the model.
  if (run.predict_delay_steps > 0 && std::abs(settings.robot.decision_period - settings.training.physics.tau) > 1e-9)
    priv.fail("predict_delay_steps", std::to_string(run.predict_delay_steps),
              "the table's model predicts in decisions of physics/tau = " +
                  SectionReader::numberText(settings.training.physics.tau) +
                  " s: it needs ~decision_period = tau, not " +
                  SectionReader::numberText(settings.robot.decision_period));
  // A greedy table not told the delay finds it (DelayEstimator), when the model's steps are its
  // decisions (as a told one needs, above).
  const bool delay_told = !source.keysUnder("predict_delay_steps").empty();
  if (!delay_told && !run.learning() &&
      std::abs(settings.robot.decision_period - settings.training.physics.tau) <= 1e-9)
    run.predict_delay_steps = kDelayFoundFromStates;
  protocol.commands_unstamped = settings.robot.command_type != CommandType::JointState;
  readFreshness(priv, settings);
  protocol.time_back_judged_by_state = run.controlling();
  protocol.starts_when_up = !run.learning() && !protocol.reset_service;
  priv.readChoice("reset_service_type", settings.reset_service_type, resetServiceTypes());
  protocol.reset_starts_in_region = settings.reset_service_type != "cartpole_qlearning/Reset";
}
}  // namespace

ControllerSettings readControllerSettings(const ParameterSource& shared, const ParameterSource& source,
                                          const ControllerContext& context)
{
  ControllerSettings settings;
  settings.training = readTrainingConfig(shared);
  RunSettings& run = settings.run;
  run.name_space = context.name_space;
  run.names = nodeSettingNames();
  settings.shutdown_when_finished = context.shutdown_by_default;
  run.config_origin = shared.origin();

  // The same reader and checks as the shared sections; a key it does not know (a typo) stops
  // the node instead of being ignored.
  SectionReader priv(source, "");
  std::string mode = "train";
  priv.readChoice("mode", mode, {"train", "evaluate", "control"});
  run.mode = mode == "control" ? RunMode::Control : mode == "evaluate" ? RunMode::Evaluate : RunMode::Train;
  priv.read("seed", run.seed, 0);
  readTablePaths(shared, priv, context, settings);
  priv.read("run_id", run.run_id);
  // Set by the controller itself, for a respawn of it to find its run.
  priv.know("run/id");
  priv.know("run/launcher");
  priv.know("run/folder");
  const EngineParams robot_engine = readEvaluation(source, priv, settings);
  priv.read("checkpoint_every", run.checkpoint_every, 0);
  priv.read("save_on_shutdown", run.save_on_shutdown);
  priv.read("shutdown_when_finished", settings.shutdown_when_finished);
  priv.readSeconds("sim_timeout", settings.sim_timeout, 0.0, 3600.0, true);
  readRobotSide(source, priv, robot_engine, settings);
  readRobots(source, priv, context, settings.robots);
  priv.read("sync", settings.sync);
  priv.read("trace", run.trace);
  run.suite_folders = context.suite_folders;
  if (run.trace && settings.training.agent.features == FeatureKind::Tiles)
    priv.fail("trace", "true", "the trace shows one table row per state: learning/features bins only");
  for (const std::string& key : context.other_keys)
    priv.know(key);
  priv.refuseUnknown();
  settings.protocol.limits = settings.training.limits;
  if (!run.learning())
    settings.warnings = drivingWarnings(settings);
  return settings;
}

std::string controllerStartText(const ControllerSettings& settings, const QTable& table,
                                const std::string& table_directory, const std::string& served)
{
  const FeatureParams& features = table.features();
  const std::string rows = features.kind == FeatureKind::Tiles ? std::to_string(features.tilings) + " tilings, " +
                                                                     std::to_string(table.stateCount()) + " tiles"
                                                               : std::to_string(table.stateCount()) + " states";
  // An evaluation says how long its episodes are and whose configuration it runs with: neither
  // need be the training's. A task that never ends on the angle has no fall to stop at.
  const bool never_ends = isSuiteTask(settings.training.task.kind);
  const std::string doing =
      settings.run.learning() ? "training"
      : settings.run.controlling()
          ? std::string(never_ends ? "controlling (greedy, no learning, no step limit; task " +
                                         toString(settings.training.task.kind) +
                                         " never ends on the angle: a pole down is swung up again) with "
                                   : "controlling (greedy, no learning, no step limit: a fall commands 0 until a "
                                     "start) with ") +
                settings.run.config_origin
          : "evaluating (greedy, no learning) in episodes of " +
                std::to_string(settings.training.task.max_episode_steps) + " steps with " + settings.run.config_origin;
  std::string text = doing + ", seed " + std::to_string(settings.run.seed) + ", " + rows + " x " +
                     std::to_string(table.actionCount()) + " actions, tables under " + table_directory + "; serving " +
                     served;
  if (settings.robots.size() > 1)
    text += settings.sync ? " in lockstep rounds" : ", each as its states come";
  if (settings.run.predict_delay_steps == kDelayFoundFromStates)
    text +=
        "; finding how many steps late the robot carries out its commands from how its states answer them, "
        "then deciding for the state predicted that far ahead (~predict_delay_steps N tells it instead)";
  else if (settings.run.predict_delay_steps > 0)
    text += "; deciding for the state predicted " + std::to_string(settings.run.predict_delay_steps) +
            (settings.run.predict_delay_steps == 1 ? " step" : " steps") + " ahead (~predict_delay_steps)";
  return text + "; " +
         (settings.protocol.reset_service ? "resets by ~" + settings.reset_service
          : settings.protocol.starts_when_up && never_ends
              ? std::string("no reset service, none needed: the task has no fall")
          : settings.protocol.starts_when_up
              ? std::string("no reset service: an episode starts when the pole is up (inside the task's "
                            "thresholds), the next at once after a step limit, and after a fall the pole stays "
                            "down until someone stands it up (the robot's own count of episodes, if it keeps one, "
                            "may differ)")
              : "no reset service: episodes start when the state is in ~start_region");
}

}  // namespace cartpole_qlearning
