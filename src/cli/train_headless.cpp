// train_headless: trains with the core alone (no ROS master), prints progress and ends with
// one line "solved=true|false episodes=N steps=M wall_s=T". With --replay it learns from the
// transitions of a file instead (the tutorial's worked example), tracing each update.
#include "cartpole_qlearning/episode_csv.h"
#include "cartpole_qlearning/headless_trainer.h"
#include "cartpole_qlearning/q_table_file.h"
#include "cartpole_qlearning/trace.h"
#include "cartpole_qlearning/transition_replay.h"

#include <ros/package.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace
{
void usage(std::ostream& out)
{
  out << "usage: train_headless [--config FILE] [--seed N] [--robots N] [--save PATH] [--ns NS] [--max-episodes N] "
         "[--stats-csv FILE] [--quiet]\n"
         "                      [--returns] [--trace] [--replay FILE]\n"
         "  --config FILE     physics, task, learning and training parameters (YAML);\n"
         "                    default: the package's config/cartpole.yaml\n"
         "  --seed N          seed of the start states and of exploration (default 0)\n"
         "  --robots N        N simulated robots feed one learner, served in lockstep rounds in robot order\n"
         "                    (as train.launch robots:=N); robot r starts from seed S + r (default 1)\n"
         "  --save PATH       write the final Q-table there (atomic); a relative PATH is taken under the\n"
         "                    controller's table folder, $ROS_HOME/cartpole_qlearning/NS (~/.ros/...), where\n"
         "                    evaluate.launch q_table:=PATH finds it; without --save nothing is written\n"
         "  --ns NS           the namespace whose table folder --save uses (default cartpole)\n"
         "  --max-episodes N  override training/max_episodes\n"
         "  --stats-csv FILE  write one CSV row per episode there as it ends (the learning curve, for\n"
         "                    rosrun cartpole_qlearning plot_learning_curve FILE); FILE is taken as given\n"
         "                    (relative to the current directory); an earlier curve there is replaced, any\n"
         "                    other file refused\n"
         "  --quiet           no progress lines, only the result line\n"
         "  --returns         before the result line, one line \"returns=R1 R2 ...\": every episode's return, in "
         "order\n"
         "  --trace           print every update as the tutorial works it (state, action, reward, next state,\n"
         "                    old Q, target, new Q) and the Q-table at each episode's end\n"
         "  --replay FILE     train on nothing else than the transitions listed in FILE ([state, action, reward,\n"
         "                    next state], states named as the config's learning/state_names), traced as --trace\n"
         "                    does; e.g. --config config/tutorial_4_states.yaml --replay "
         "config/tutorial_10_steps.yaml\n";
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
}  // namespace

int run(int argc, char** argv)
{
  using namespace cartpole_qlearning;
  std::string config_path;
  std::string save_path;
  std::string stats_csv_path;
  std::string name_space = "/cartpole";
  std::uint64_t seed = 0;
  std::uint64_t max_episodes = 0;
  std::uint64_t robots = 1;
  bool quiet = false;
  bool print_returns = false;
  bool trace = false;
  std::string replay_path;
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
    else if (arg == "--replay" && has_value)
      replay_path = argv[++i];
    else if (arg == "--config" && has_value)
      config_path = argv[++i];
    else if (arg == "--save" && has_value)
      save_path = argv[++i];
    else if (arg == "--stats-csv" && has_value)
      stats_csv_path = argv[++i];
    else if (arg == "--ns" && has_value)
    {
      name_space = argv[++i];
      if (name_space.empty() || name_space.find("..") != std::string::npos)
      {
        std::cerr << "train_headless: --ns '" << name_space << "' is not allowed (must be a ROS namespace)\n";
        return 2;
      }
      if (name_space.front() != '/')
        name_space = "/" + name_space;
    }
    else if (arg == "--seed" && has_value)
    {
      if (!parseCount(argv[++i], seed))
      {
        std::cerr << "train_headless: --seed " << argv[i] << " is not allowed (must be a whole number >= 0)\n";
        return 2;
      }
    }
    else if (arg == "--robots" && has_value)
    {
      if (!parseCount(argv[++i], robots) || robots == 0 || robots > 1000)
      {
        std::cerr << "train_headless: --robots " << argv[i]
                  << " is not allowed (must be a whole number in [1, 1000])\n";
        return 2;
      }
    }
    else if (arg == "--max-episodes" && has_value)
    {
      if (!parseCount(argv[++i], max_episodes) || max_episodes == 0)
      {
        std::cerr << "train_headless: --max-episodes " << argv[i] << " is not allowed (must be a whole number >= 1)\n";
        return 2;
      }
    }
    else
    {
      std::cerr << "train_headless: unknown or incomplete argument '" << arg << "'\n";
      usage(std::cerr);
      return 2;
    }
  }

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

  // The one path rule: a relative table path is under the table folder (as the controller's
  // services and the launch files take it); an absolute one is the user's own.
  const std::string table_dir = defaultTableDirectory(name_space);
  const auto save = [&](const QTable& table) {
    if (!save_path.empty())
    {
      try
      {
        std::string written = save_path;
        if (save_path.front() == '/')
          saveQTableFile(table, save_path);
        else
        {
          saveQTableUnder(table, table_dir, save_path);
          written = resolvePathUnder(table_dir, save_path);
        }
        if (!quiet)
          std::printf("saved the Q-table to %s\n", written.c_str());
      }
      catch (const QTableFileError& e)
      {
        std::cerr << "train_headless: " << e.what() << "\n";
        return 1;
      }
    }
    else if (!quiet)
    {
      std::printf("nothing saved (--save NAME writes the table to %s/NAME)\n", table_dir.c_str());
    }
    return 0;
  };

  // Only the trace and the replay name states (one name per table row: built for them alone).
  const std::vector<std::string> names =
      trace || !replay_path.empty() ? stateNames(config.agent) : std::vector<std::string>();
  if (!replay_path.empty())
  {
    if (robots != 1 || max_episodes != 0 || !stats_csv_path.empty())
    {
      std::cerr << "train_headless: --replay learns from its file alone: --robots, --max-episodes and --stats-csv do "
                   "not apply\n";
      return 2;
    }
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
    return save(agent.table());
  }

  // Opened before training, so that a path that cannot be written is said at once.
  std::unique_ptr<EpisodeCsvWriter> stats_csv;
  if (!stats_csv_path.empty())
  {
    try
    {
      stats_csv = std::make_unique<EpisodeCsvWriter>(AppendingFile::open(stats_csv_path));
    }
    catch (const FileError& e)
    {
      std::cerr << "train_headless: --stats-csv: " << e.what() << "\n";
      return 2;
    }
  }

  HeadlessTrainer trainer(config, seed, robots);
  if (trace)
  {
    trainer.session().setTrace([&](std::size_t robot, const TraceStep& step) {
      const std::string who = robots > 1 ? "robot " + std::to_string(robot) + ": " : std::string();
      std::printf("%s%s\n", who.c_str(), traceLine(step, names, config.agent.actions).c_str());
    });
  }
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t every = quiet ? 0 : config.limits.progress_every;
  std::uint64_t last_steps = 0;
  auto last_time = start;
  std::string returns;
  // The robots' names in the CSV, as train.launch robots:=N gives them.
  const std::vector<std::string> robot_names = robotNamespaces(robots);
  const TrainingResult result = trainer.run([&](const EpisodeSummary& s) {
    if (print_returns)
    {
      char text[32];
      std::snprintf(text, sizeof text, "%s%.17g", returns.empty() ? "" : " ", s.episode_return);
      returns += text;
    }
    if (trace)
    {
      const std::string which = robots > 1 ? "robot " + std::to_string(s.robot) + "'s episode " +
                                                 std::to_string(s.robot_episode) + " (" + std::to_string(s.episode) +
                                                 " in all)"
                                           : "episode " + std::to_string(s.episode);
      std::printf("Q-table after %s:\n%s\n", which.c_str(), qTableText(trainer.session().table(), names).c_str());
    }
    if (stats_csv)
    {
      const std::string& robot = robot_names[s.robot];
      const double now = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
      try
      {
        stats_csv->write(s, robot, now);
      }
      catch (const FileError& e)
      {
        // The curve is a by-product: training goes on, and its table is still saved.
        std::cerr << "train_headless: --stats-csv: " << e.what() << "; the learning curve stops at episode "
                  << s.episode - 1 << ", training goes on\n";
        stats_csv.reset();
      }
    }
    if (every == 0 || (s.episode % every != 0 && !config.limits.reached(s.episode, s.solved)))
      return;
    const auto now = std::chrono::steady_clock::now();
    const double interval = std::chrono::duration<double>(now - last_time).count();
    const double rate = interval > 0.0 ? static_cast<double>(s.total_steps - last_steps) / interval : 0.0;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    std::printf("%s\n", progressLine(s, config.task.solved_window, rate, elapsed).c_str());
    last_steps = s.total_steps;
    last_time = now;
  });
  const int status = save(trainer.session().table());
  if (print_returns)
    std::printf("returns=%s\n", returns.c_str());
  // Microseconds: a run to solved takes a few milliseconds.
  std::printf("solved=%s episodes=%llu steps=%llu wall_s=%.6f\n", result.solved ? "true" : "false",
              static_cast<unsigned long long>(result.episodes), static_cast<unsigned long long>(result.steps),
              result.wall_s);
  return status;
}

int main(int argc, char** argv)
{
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
