// train_headless: the controller node's application with the core alone (no ROS master): it
// trains (from scratch, from a table, or on from a run's checkpoint) or evaluates a table
// greedily, making the same RunApplication calls as the node, and prints what the node logs.
// Training ends with one line "solved=true|false episodes=N steps=M wall_s=T", an evaluation
// with "evaluated=N balanced=M mean_return=R", a robustness suite (--evaluate TABLE --suite FILE)
// with "suite=PASSED|FAILED cases=N passed=K worst=M/E". With --replay it learns from the transitions of a
// file instead (the tutorial's worked example), tracing each update. --policy TABLE prints the
// table's greedy policy over a grid of states as CSV (scripts/plot_policy draws it).
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/learning/policy_grid.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/application/run_application.h"
#include "cartpole_qlearning/learning/trace.h"
#include "cartpole_qlearning/application/run_folder.h"
#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/learning/transition_replay.h"

#include <ros/package.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>

namespace
{
std::atomic<int> g_signal{0};
std::atomic<bool> g_stop{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "set from a signal handler");

void onSignal(int signal)
{
  g_signal.store(signal);
  g_stop.store(true);
}

void usage(std::ostream& out)
{
  out << "usage: train_headless [--config FILE] [--seed N] [--robots N] [--ns NS] [--max-episodes N] [--save PATH]\n"
         "                      [--load TABLE | --resume FOLDER] [--checkpoint-every N] [--no-run-folder]\n"
         "                      [--stats-csv FILE] [--quiet] [--returns] [--trace]\n"
         "       train_headless --evaluate TABLE [--episodes N] [--config FILE] [--seed N] [--robots N] [--ns NS]\n"
         "       train_headless --evaluate TABLE --suite FILE [--config FILE] [--seed N] [--ns NS] [--quiet]\n"
         "       train_headless --replay FILE [--config FILE] [--seed N] [--save PATH]\n"
         "       train_headless --policy TABLE [--grid N] [--axes X,Y] [--at NAME=V,...] [--previous none|A] [--ns "
         "NS]\n"
         "Trains as train.launch's controller does, with the core alone (no ROS master), writes what it writes and\n"
         "prints what it logs. Training ends with \"solved=true|false episodes=N steps=M wall_s=T\" (N and M count\n"
         "a loaded or resumed table's own), an evaluation with \"evaluated=N balanced=M mean_return=R\".\n"
         "Paths (--save, --load, --resume, --evaluate, --stats-csv): a relative path is under the table folder\n"
         "$ROS_HOME/cartpole_qlearning/NS (~/.ros/cartpole_qlearning/cartpole by default), where the launch files\n"
         "and the controller's services look; an absolute path is your own (links followed as the shell would).\n"
         "A training run has its own folder there, runs/<date>_<time>_<ns>_seed<N>, as the controller's has: its\n"
         "table at every checkpoint, at the end and on Ctrl-C (q_table.yaml), its record (run.yaml) and its curve\n"
         "(episodes.csv). A solved run also replaces the default table; an unsolved one leaves it as it was.\n"
         "  --config FILE        physics, task, learning and training parameters (YAML); default: the package's\n"
         "                       config/cartpole.yaml\n"
         "  --seed N             seed of the start states and of exploration (default 0; with --resume the run's)\n"
         "  --robots N           N simulated robots feed one learner, served in lockstep rounds in robot order, as\n"
         "                       train.launch robots:=N (named by its namespaces robot_0 ...); robot r starts from\n"
         "                       seed N + r (default 1)\n"
         "  --ns NS              the namespace whose table folder the paths are under (default cartpole)\n"
         "  --max-episodes N     override training/max_episodes (a loaded or resumed table's episodes count)\n"
         "  --save PATH          the default table (the controller's ~q_table_path; default q_table.yaml, which\n"
         "                       evaluate.launch loads), replaced only by a solved run\n"
         "  --checkpoint-every N a checkpoint into the run's folder every N episodes (default 100; 0: none)\n"
         "  --no-run-folder      write no run folder (no checkpoints, record or curve, nothing on Ctrl-C) and no\n"
         "                       table but --save's (when solved): for scripts that run it many times\n"
         "  --load TABLE         train further from a table: its episode and step counts go on, and with them the\n"
         "                       schedules (epsilon, alpha) and --max-episodes\n"
         "  --resume FOLDER      go on from the last checkpoint of a run folder under the table folder (runs/...,\n"
         "                       as a run's first line says): its counters, schedules, solved window and curve;\n"
         "                       give the run's --config and --robots. A finished run has nothing left to do:\n"
         "                       --load its q_table.yaml to train it further\n"
         "  --evaluate TABLE     run TABLE greedily, learning nothing and writing nothing; then M is how many of\n"
         "                       the N episodes balanced to the step limit, R the mean return of the last\n"
         "                       task/solved_window episodes (100: all of them by default)\n"
         "  --episodes N         with --evaluate: how many episodes (default 100)\n"
         "  --suite FILE         with --evaluate: run TABLE greedily on each case of a robustness suite\n"
         "                       (config/robust_suite.yaml: its episodes, pass counts and seed; --seed N replaces\n"
         "                       the seed; the cases vary --config's physics), print a table of balanced episodes\n"
         "                       per case and end with \"suite=PASSED|FAILED cases=N passed=K worst=M/E\" (M of E\n"
         "                       episodes balanced in the worst case); exit 0 whatever the verdict\n"
         "  --stats-csv FILE     one CSV row per episode, as each ends (the learning curve, for rosrun\n"
         "                       cartpole_qlearning plot_learning_curve FILE) instead of the run's episodes.csv;\n"
         "                       none: no curve. An earlier curve there is replaced, any other file refused\n"
         "  --quiet              nothing but warnings, errors, the robustness of the saved table (one line) and the\n"
         "                       result line\n"
         "  --returns            before the result line, one line \"returns=R1 R2 ...\": every episode's return\n"
         "                       in order\n"
         "  --trace              print every update as the tutorial works it (state, action, reward, next state,\n"
         "                       old Q, target, new Q) and the Q-table at each episode's end\n"
         "  --replay FILE        train on nothing else than the transitions listed in FILE ([state, action,\n"
         "                       reward, next state], states named as the config's learning/state_names), traced\n"
         "                       as --trace does; --save writes its table; e.g. --config\n"
         "                       config/tutorial_4_states.yaml --replay config/tutorial_10_steps.yaml\n"
         "  --policy TABLE       print TABLE's greedy policy as CSV: on an N x N grid over two state dimensions\n"
         "                       (the table's bounds), the action the controller takes and max_a Q, found by the\n"
         "                       table's own features (for rosrun cartpole_qlearning plot_policy); learns and\n"
         "                       writes nothing\n"
         "  --grid N             with --policy: points per axis, in [2, "
      << cartpole_qlearning::kMaxPolicyGridPoints
      << "] (default 101)\n"
         "  --axes X,Y           with --policy: the two dimensions among x, x_dot, theta, theta_dot (default\n"
         "                       theta,theta_dot)\n"
         "  --at NAME=V,...      with --policy: the values of the other dimensions (default 0)\n"
         "  --previous none|A    with --policy, for a table that sees its previous action: none (an episode's\n"
         "                       first state, the default) or the index of the action taken last\n"
         "Ctrl-C (SIGINT) or SIGTERM saves the table into the run's folder, as the controller does when stopped,\n"
         "and exits with 128 + the signal's number. Exit 1: a table could not be saved; 2: a bad argument, config,\n"
         "table or folder (the message names it).\n";
}

bool parseCount(const std::string& text, std::uint64_t& value)
{
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
    return false;
  try
  {
    value = std::stoull(text);
  }
  catch (const std::exception&)
  {
    return false;
  }
  return true;
}

std::string defaultConfigPath()
{
  const std::string share = ros::package::getPath("cartpole_qlearning");
  return share.empty() ? std::string() : share + "/config/cartpole.yaml";
}

// What the application says: information on stdout (none with --quiet), the rest on stderr.
// Returns whether an error was said.
bool say(const cartpole_qlearning::LogLines& log, bool quiet)
{
  using cartpole_qlearning::LogLine;
  bool error = false;
  for (const LogLine& s : log)
  {
    error = error || s.level == LogLine::Level::Error;
    if (s.level == LogLine::Level::Info)
    {
      if (!quiet)
        std::printf("%s\n", s.text.c_str());
    }
    else
    {
      std::fflush(stdout);
      std::fprintf(stderr, "train_headless: %s\n", s.text.c_str());
    }
  }
  return error;
}

// Tables as the command line names them: an absolute path is the user's own, a relative one
// under the table folder.
cartpole_qlearning::TableStore commandLineTables(const std::string& table_dir)
{
  return cartpole_qlearning::TableStore(table_dir, "", cartpole_qlearning::AbsolutePaths::AreTheUsersFiles);
}
// --evaluate TABLE --suite FILE: every case of the suite, greedily; exit 0 when it ran (the verdict
// is in the last line), 2 on a bad suite, table or configuration.
int runSuite(const cartpole_qlearning::TrainingConfig& config, const std::string& suite_path,
             const std::string& table_path, const std::string& table_dir, bool seed_given, std::uint64_t seed,
             bool quiet)
{
  using namespace cartpole_qlearning;
  RobustnessSuite suite;
  try
  {
    suite = loadRobustnessSuite(suite_path, config);
  }
  catch (const ConfigError& e)
  {
    std::cerr << "train_headless: --suite: " << e.what() << "\n";
    return 2;
  }
  if (seed_given)
    suite.seed = seed;
  SuiteResult result;
  try
  {
    const QTable table = commandLineTables(table_dir).load(table_path);
    result = cartpole_qlearning::evaluateSuite(table, config, suite);
  }
  catch (const std::runtime_error& e)  // FileError, ConfigError: the table cannot be read or does not fit
  {
    std::cerr << "train_headless: --evaluate " << table_path << ": " << e.what() << "\n";
    return 2;
  }
  if (!quiet)
    std::printf("suite %s: %zu cases, %llu greedy episodes each, seed %llu\n%s\n", suite_path.c_str(),
                suite.cases.size(), static_cast<unsigned long long>(suite.episodes),
                static_cast<unsigned long long>(suite.seed), result.table().c_str());
  std::size_t passed = 0;
  for (const CaseResult& c : result.cases)
    passed += c.passed();
  std::printf("suite=%s cases=%zu passed=%zu worst=%llu/%llu\n", result.passed() ? "PASSED" : "FAILED",
              result.cases.size(), passed, static_cast<unsigned long long>(result.worstBalanced()),
              static_cast<unsigned long long>(suite.episodes));
  return 0;
}
// --policy TABLE: the table's greedy policy over a grid, as CSV on stdout. Exit 2 on a table that
// cannot be read or a bad grid, the message naming what.
int printPolicy(const std::string& table_path, const std::string& table_dir, std::uint64_t points,
                const std::string& axes, const std::string& at, const std::string& previous)
{
  using namespace cartpole_qlearning;
  PolicyGridParams params;
  params.points = points;
  try
  {
    const std::size_t comma = axes.find(',');
    if (comma == std::string::npos)
      throw std::invalid_argument("give two dimensions, e.g. theta,theta_dot");
    params.x_dimension = stateDimension(axes.substr(0, comma));
    params.y_dimension = stateDimension(axes.substr(comma + 1));
    if (params.x_dimension == params.y_dimension)
      throw std::invalid_argument("the two axes must be two different dimensions");
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "train_headless: --axes " << axes << " is not allowed (" << e.what() << ")\n";
    return 2;
  }
  std::string rest = at;
  while (!rest.empty())
  {
    const std::string item = rest.substr(0, rest.find(','));
    rest = item.size() < rest.size() ? rest.substr(item.size() + 1) : std::string();
    const std::size_t equals = item.find('=');
    try
    {
      if (equals == std::string::npos)
        throw std::invalid_argument("give NAME=VALUE, e.g. x=0.5");
      const std::size_t d = stateDimension(item.substr(0, equals));
      if (d == params.x_dimension || d == params.y_dimension)
        throw std::invalid_argument(item.substr(0, equals) + " is an axis");
      std::size_t used = 0;
      const std::string value = item.substr(equals + 1);
      params.slice[d] = std::stod(value, &used);
      if (used != value.size())
        throw std::invalid_argument("not a number: " + value);
    }
    catch (const std::logic_error& e)  // invalid_argument, out_of_range
    {
      std::cerr << "train_headless: --at " << at << " is not allowed (" << e.what() << ")\n";
      return 2;
    }
  }
  QTable table;
  try
  {
    table = commandLineTables(table_dir).load(table_path);
  }
  catch (const FileError& e)
  {
    std::cerr << "train_headless: --policy " << table_path << ": " << e.what() << "\n";
    return 2;
  }
  if (previous != "none")
  {
    std::uint64_t index = 0;
    if (!parseCount(previous, index) || index >= table.actionCount())
    {
      std::cerr << "train_headless: --previous " << previous << " is not allowed (none, or an action index below "
                << table.actionCount() << ")\n";
      return 2;
    }
    params.previous = index + 1;
  }
  try
  {
    const PolicyGrid grid = policyGrid(table, params);
    std::fputs(policyGridCsv(grid, table).c_str(), stdout);
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "train_headless: --policy " << table_path << ": " << e.what() << "\n";
    return 2;
  }
  return 0;
}
}  // namespace

int run(int argc, char** argv)
{
  using namespace cartpole_qlearning;
  std::string config_path;
  std::string save_path;
  std::string stats_csv_path;
  std::string name_space = "/cartpole";
  std::string load_path;
  std::string resume_folder;
  std::string evaluate_path;
  std::string suite_path;
  std::uint64_t seed = 0;
  bool seed_given = false;
  std::uint64_t max_episodes = 0;
  std::uint64_t robots = 1;
  std::uint64_t checkpoint_every = RunSettings().checkpoint_every;
  bool checkpoint_given = false;
  std::uint64_t evaluation_episodes = 100;
  bool episodes_given = false;
  bool no_run_folder = false;
  bool quiet = false;
  bool print_returns = false;
  bool trace = false;
  std::string replay_path;
  std::string policy_path;
  std::uint64_t grid_points = cartpole_qlearning::PolicyGridParams().points;
  std::string axes = "theta,theta_dot";
  std::string policy_at;
  std::string previous = "none";
  bool policy_options = false;
  // A value argument: its text, or a refusal that names it.
  const auto refuse = [](const std::string& arg, const std::string& value, const std::string& allowed) {
    std::cerr << "train_headless: " << arg << " " << value << " is not allowed (" << allowed << ")\n";
    return 2;
  };
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--help" || arg == "-h")
    {
      usage(std::cout);
      return 0;
    }
    else if (arg == "--quiet")
      quiet = true;
    else if (arg == "--returns")
      print_returns = true;
    else if (arg == "--trace")
      trace = true;
    else if (arg == "--no-run-folder")
      no_run_folder = true;
    else if (arg == "--replay" && has_value)
      replay_path = argv[++i];
    else if (arg == "--policy" && has_value)
      policy_path = argv[++i];
    else if (arg == "--axes" && has_value)
    {
      policy_options = true;
      axes = argv[++i];
    }
    else if (arg == "--at" && has_value)
    {
      policy_options = true;
      policy_at = argv[++i];
    }
    else if (arg == "--previous" && has_value)
    {
      policy_options = true;
      previous = argv[++i];
    }
    else if (arg == "--grid" && has_value)
    {
      policy_options = true;
      if (!parseCount(argv[++i], grid_points) || grid_points < 2 ||
          grid_points > cartpole_qlearning::kMaxPolicyGridPoints)
        return refuse(
            arg, argv[i],
            "must be a whole number in [2, " + std::to_string(cartpole_qlearning::kMaxPolicyGridPoints) + "]");
    }
    else if (arg == "--config" && has_value)
      config_path = argv[++i];
    else if (arg == "--save" && has_value)
      save_path = argv[++i];
    else if (arg == "--stats-csv" && has_value)
      stats_csv_path = argv[++i];
    else if (arg == "--load" && has_value)
      load_path = argv[++i];
    else if (arg == "--resume" && has_value)
      resume_folder = argv[++i];
    else if (arg == "--evaluate" && has_value)
      evaluate_path = argv[++i];
    else if (arg == "--suite" && has_value)
      suite_path = argv[++i];
    else if (arg == "--ns" && has_value)
    {
      name_space = argv[++i];
      if (name_space.empty() || name_space.find("..") != std::string::npos)
        return refuse(arg, "'" + name_space + "'", "must be a ROS namespace");
      if (name_space.front() != '/')
        name_space = "/" + name_space;
    }
    else if (arg == "--seed" && has_value)
    {
      seed_given = true;
      if (!parseCount(argv[++i], seed))
        return refuse(arg, argv[i], "must be a whole number >= 0");
    }
    else if (arg == "--robots" && has_value)
    {
      if (!parseCount(argv[++i], robots) || robots == 0 || robots > 1000)
        return refuse(arg, argv[i], "must be a whole number in [1, 1000]");
    }
    else if (arg == "--max-episodes" && has_value)
    {
      if (!parseCount(argv[++i], max_episodes) || max_episodes == 0)
        return refuse(arg, argv[i], "must be a whole number >= 1");
    }
    else if (arg == "--checkpoint-every" && has_value)
    {
      checkpoint_given = true;
      if (!parseCount(argv[++i], checkpoint_every))
        return refuse(arg, argv[i], "must be a whole number >= 0; 0: no checkpoints");
    }
    else if (arg == "--episodes" && has_value)
    {
      episodes_given = true;
      if (!parseCount(argv[++i], evaluation_episodes) || evaluation_episodes == 0)
        return refuse(arg, argv[i], "must be a whole number >= 1");
    }
    else
    {
      std::cerr << "train_headless: unknown or incomplete argument '" << arg << "'\n";
      usage(std::cerr);
      return 2;
    }
  }

  // Options that do not go together, each named.
  const bool evaluating = !evaluate_path.empty();
  const auto conflict = [](const std::string& what, const std::string& why) {
    std::cerr << "train_headless: " << what << ": " << why << "\n";
    return 2;
  };
  if (policy_options && policy_path.empty())
    return conflict("--grid, --axes, --at and --previous", "draw a table's policy: give them with --policy TABLE");
  if (!policy_path.empty())
  {
    // A policy is read from the table alone (the file says its features and actions): nothing to
    // train, evaluate or configure.
    for (int i = 1; i < argc; ++i)
    {
      const std::string arg = argv[i];
      if (arg == "--policy" || arg == "--grid" || arg == "--axes" || arg == "--at" || arg == "--previous" ||
          arg == "--ns")
        ++i;
      else
        return conflict(arg + " with --policy", "a policy is drawn from the table alone (its file says its features)");
    }
    return printPolicy(policy_path, defaultTableDirectory(name_space), grid_points, axes, policy_at, previous);
  }
  if (!load_path.empty() && !resume_folder.empty())
    return conflict("--load and --resume", "give one: --resume goes on from a run's own checkpoint");
  if (episodes_given && !evaluating)
    return conflict("--episodes", "counts --evaluate's episodes (training: --max-episodes)");
  if (evaluating)
  {
    for (const auto& [name, given] : {std::pair<std::string, bool>{"--load", !load_path.empty()},
                                      {"--resume", !resume_folder.empty()},
                                      {"--save", !save_path.empty()},
                                      {"--max-episodes", max_episodes != 0},
                                      {"--checkpoint-every", checkpoint_given},
                                      {"--no-run-folder", no_run_folder},
                                      {"--stats-csv", !stats_csv_path.empty()},
                                      {"--trace", trace},
                                      {"--replay", !replay_path.empty()}})
      if (given)
        return conflict(name + " with --evaluate", "an evaluation learns nothing and writes nothing");
  }
  if (!replay_path.empty())
  {
    for (const auto& [name, given] : {std::pair<std::string, bool>{"--robots", robots != 1},
                                      {"--max-episodes", max_episodes != 0},
                                      {"--stats-csv", !stats_csv_path.empty()},
                                      {"--load", !load_path.empty()},
                                      {"--resume", !resume_folder.empty()},
                                      {"--checkpoint-every", checkpoint_given},
                                      {"--no-run-folder", no_run_folder}})
      if (given)
        return conflict(name + " with --replay", "a replay learns from its file alone");
  }
  if (!suite_path.empty())
  {
    if (!evaluating)
      return conflict("--suite", "runs a table: give it with --evaluate TABLE");
    for (const auto& [name, given] : {std::pair<std::string, bool>{"--episodes", episodes_given},
                                      {"--robots", robots != 1},
                                      {"--returns", print_returns}})
      if (given)
        return conflict(name + " with --suite", "the suite file gives each case's episodes, run on one robot");
  }
  if (no_run_folder && checkpoint_given && checkpoint_every > 0)
    return conflict("--checkpoint-every with --no-run-folder", "checkpoints go into the run's folder");

  if (config_path.empty())
  {
    config_path = defaultConfigPath();
    if (config_path.empty())
    {
      std::cerr << "train_headless: package cartpole_qlearning not found (source devel/setup.bash) "
                   "and no --config given\n";
      return 2;
    }
  }

  TrainingConfig config;
  try
  {
    const auto source = loadYamlParameters(config_path);
    refuseUnknownSections(*source);
    config = readTrainingConfig(*source);
  }
  catch (const ConfigError& e)
  {
    std::cerr << "train_headless: " << e.what() << "\n";
    return 2;
  }
  if (max_episodes > 0)
    config.limits.max_episodes = max_episodes;
  if ((trace || !replay_path.empty()) && config.agent.features == FeatureKind::Tiles)
  {
    std::cerr << "train_headless: " << (trace ? "--trace" : "--replay")
              << " shows one table row per state: it needs learning/features bins (" << config_path << " has tiles)\n";
    return 2;
  }
  const std::string table_dir = defaultTableDirectory(name_space);
  // A relative --save must stay in the table folder, as over a service: said before training.
  if (!save_path.empty() && save_path.front() != '/')
  {
    try
    {
      relativePathUnder(table_dir, save_path);
    }
    catch (const FileError& e)
    {
      return refuse("--save", save_path, e.what());
    }
  }

  if (!suite_path.empty())
    return runSuite(config, suite_path, evaluate_path, table_dir, seed_given, seed, quiet);

  // Only the trace and the replay name states (one name per table row: built for them alone).
  const std::vector<std::string> names =
      trace || !replay_path.empty() ? stateNames(config.agent) : std::vector<std::string>();
  if (!replay_path.empty())
  {
    // Every line is checked before the first update: a bad file changes nothing.
    std::vector<ReplayTransition> transitions;
    try
    {
      transitions = loadReplay(replay_path, names, config.agent.actions.size());
    }
    catch (const ReplayError& e)
    {
      std::cerr << "train_headless: " << e.what() << "\n";
      return 2;
    }
    QLearningAgent agent(config.agent, seed);
    std::printf("replaying %zu transitions of %s (gamma %s, alpha %s at episode 1)\n", transitions.size(),
                replay_path.c_str(), traceNumber(config.agent.gamma).c_str(), traceNumber(agent.alpha(0)).c_str());
    std::size_t number = 0;
    replayTransitions(
        agent, transitions,
        [&](const ReplayTransition& t, const TraceStep& step) {
          std::printf("#%zu (line %d) %s\n", ++number, t.line, traceLine(step, names, config.agent.actions).c_str());
        },
        [&](std::uint64_t episode) {
          std::printf("Q-table after episode %llu:\n%s\n", static_cast<unsigned long long>(episode),
                      qTableText(agent.table(), names).c_str());
        });
    std::printf("Q-table after transition %zu (the end of the replay):\n%s\n", transitions.size(),
                qTableText(agent.table(), names).c_str());
    if (save_path.empty())
      return 0;
    try
    {
      commandLineTables(table_dir).save(agent.table(), save_path);
      if (!quiet)
        std::printf("saved the Q-table to %s\n", commandLineTables(table_dir).resolve(save_path).c_str());
    }
    catch (const FileError& e)
    {
      std::cerr << "train_headless: --save: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }

  // --resume: the run's own seed unless another is given (its record says which).
  RunRecord resumed;
  if (!resume_folder.empty())
  {
    try
    {
      resumed = parseRunRecord(readFileUnder(table_dir, resume_folder + "/" + kRunRecordFile, 1 << 20));
      if (!seed_given)
        seed = resumed.seed;
    }
    catch (const FileError&)
    {
      // RunApplication::resume says what is wrong with the folder.
    }
  }

  // Training goes on from a table's episode count, and max_episodes counts it: a table at or past
  // it has nothing to train (else one episode would run). A resumed run goes on from its
  // checkpoint table's count, not its record's: a kill between the two saves leaves the record a
  // checkpoint behind, and the table wins (RunApplication::resume). A resumed run that has
  // finished says so below; a table that cannot be read is said by RunApplication.
  if (!resume_folder.empty() || !load_path.empty())
  {
    std::uint64_t episodes = 0;
    try
    {
      episodes =
          !resume_folder.empty()
              ? (resumed.finished.empty() ? loadQTableUnder(table_dir, resume_folder + "/" + kRunTableFile).episodes
                                          : 0)
              : commandLineTables(table_dir).load(load_path).episodes;
    }
    catch (const FileError&)
    {
    }
    if (episodes >= config.limits.max_episodes)
    {
      std::cerr << "train_headless: " << (resume_folder.empty() ? "--load " + load_path : "--resume " + resume_folder)
                << ": its table has " << episodes << " episodes of training already, and training ends at episode "
                << config.limits.max_episodes << " (--max-episodes, else training/max_episodes): nothing to train\n";
      return 2;
    }
  }

  // The settings the controller reads from its private parameters, from the command line.
  RunSettings settings;
  settings.learning = !evaluating;
  settings.seed = seed;
  settings.name_space = name_space;
  settings.q_table_dir = table_dir;
  if (!save_path.empty())
    settings.q_table_path = save_path;
  else if (no_run_folder)
    settings.q_table_path.clear();  // no default table either
  settings.load_on_start = evaluating ? evaluate_path : load_path;
  settings.stats_csv = !stats_csv_path.empty() ? stats_csv_path : no_run_folder ? "none" : "";
  settings.evaluation_episodes = evaluation_episodes;
  settings.checkpoint_every = no_run_folder ? 0 : checkpoint_every;
  settings.save_on_shutdown = !no_run_folder;
  settings.run_folder = !no_run_folder;
  settings.trace = trace;
  settings.own_absolute_paths = true;
  // A relative training/suite: beside the config first, then the package's config/.
  const std::string config_folder = config_path.substr(0, config_path.find_last_of('/') + 1);
  settings.suite_folders = {config_folder.empty() ? "." : config_folder.substr(0, config_folder.size() - 1)};
  if (!ros::package::getPath("cartpole_qlearning").empty())
    settings.suite_folders.push_back(ros::package::getPath("cartpole_qlearning") + "/config");

  HeadlessTrainer trainer(config, seed, robots, !evaluating);
  const std::vector<std::string> robot_names = robotNamespaces(robots);
  std::unique_ptr<RunApplication> application;
  bool error = false;
  try
  {
    application = std::make_unique<RunApplication>(settings, config, trainer.session());
    if (!evaluating && trace)
      trainer.session().setTrace([&](std::size_t robot, const TraceStep& step) {
        const std::string& name = robot_names[robot];
        std::printf("%s%s\n", robots > 1 ? (name + ": ").c_str() : "",
                    traceLine(step, names, config.agent.actions).c_str());
      });
    error = say(resume_folder.empty() ? application->start() : application->resume(resume_folder), quiet);
  }
  catch (const RunSettingError& e)
  {
    std::cerr << "train_headless: --stats-csv " << stats_csv_path << " is not allowed (" << e.why << ")\n";
    return 2;
  }
  catch (const ConfigError& e)
  {
    // Named by the option whose table or folder it is.
    const std::string option = !resume_folder.empty() ? "--resume " + resume_folder + ": "
                               : evaluating           ? "--evaluate " + evaluate_path + ": "
                               : !load_path.empty()   ? "--load " + load_path + ": "
                                                      : "";
    std::cerr << "train_headless: " << option << e.what() << "\n";
    return 2;
  }
  if (application->finished())
  {
    // A resumed run that had finished: nothing to train; its counts, as a result line.
    const EpisodeSummary& last = trainer.session().lastEpisode();
    std::printf("solved=%s episodes=%llu steps=%llu wall_s=0.000000\n", resumed.finished == "solved" ? "true" : "false",
                static_cast<unsigned long long>(last.episode), static_cast<unsigned long long>(last.total_steps));
    return 0;
  }

  struct sigaction action = {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);

  std::string returns;
  const TrainingResult result = trainer.runUntil(
      [&](const EpisodeSummary& s) {
        if (print_returns)
        {
          char text[32];
          std::snprintf(text, sizeof text, "%s%.17g", returns.empty() ? "" : " ", s.episode_return);
          returns += text;
        }
        const bool training_finished = !evaluating && config.limits.reached(s.episode, s.solved);
        const EpisodeEnd end = application->endEpisode(robot_names[s.robot], training_finished);
        error = say(end.log, quiet) || error;
        // What the saved table is worth is a result, as the result line is: --quiet keeps it.
        if (quiet && !end.robustness.empty())
          std::printf("robustness of the saved table: %s\n", end.robustness.c_str());
        return end.finished || training_finished;
      },
      &g_stop);
  const bool stopped = g_stop.load();
  if (stopped)
  {
    std::fflush(stdout);
    std::fprintf(stderr, "train_headless: stopped by %s\n", g_signal.load() == SIGINT ? "SIGINT" : "SIGTERM");
    error = say(application->shutdown(), quiet) || error;
  }
  if (print_returns)
    std::printf("returns=%s\n", returns.c_str());
  if (evaluating)
  {
    const EvaluationVerdict verdict = application->verdict();
    std::printf("evaluated=%llu balanced=%llu mean_return=%.3f\n", static_cast<unsigned long long>(verdict.episodes),
                static_cast<unsigned long long>(verdict.balanced), shownReturn(verdict.mean_return, 3));
  }
  else
  {
    // A solved run's default table that could not be written is said in the final line above;
    // it is an error all the same.
    const EpisodeSummary& end = trainer.session().lastEpisode();
    if (!stopped && end.solved && !settings.q_table_path.empty())
    {
      bool written = false;
      try
      {
        const QTable saved = loadQTableFile(application->resolve(""));
        written =
            saved.episodes == trainer.session().table().episodes && saved.steps == trainer.session().table().steps;
      }
      catch (const FileError&)
      {
      }
      if (!written)
      {
        std::fflush(stdout);
        std::fprintf(stderr, "train_headless: the table was not saved to %s\n", application->resolve("").c_str());
        error = true;
      }
    }
    // The session's counts: a loaded or resumed table's episodes included, as the node counts them.
    // Microseconds: a run to solved takes a few milliseconds.
    const EpisodeSummary& last = trainer.session().lastEpisode();
    std::printf("solved=%s episodes=%llu steps=%llu wall_s=%.6f\n", result.solved ? "true" : "false",
                static_cast<unsigned long long>(last.episode), static_cast<unsigned long long>(last.total_steps),
                result.wall_s);
  }
  return stopped ? 128 + g_signal.load() : error ? 1 : 0;
}

int main(int argc, char** argv)
{
  // Line by line, as the node logs: a log file followed with tail -f (or cut short by kill -9)
  // holds whole lines up to the last one said.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // What the checks above did not foresee still ends with a message and exit 2, not an abort.
  try
  {
    return run(argc, argv);
  }
  catch (const std::exception& e)
  {
    std::cerr << "train_headless: " << e.what() << "\n";
    return 2;
  }
}
