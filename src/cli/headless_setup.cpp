// What train_headless's modes share: the configuration, printing what the application says, and
// the tables read and written by the services' path rule.
#include "headless_modes.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/node_settings/table_folder.h"
#include "cartpole_qlearning/learning/table_config.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
bool isThisPackage(const std::filesystem::path& folder)
{
  std::ifstream manifest(folder / "package.xml");
  if (!manifest)
    return false;
  std::ostringstream text;
  text << manifest.rdbuf();
  return text.str().find("<name>cartpole_qlearning</name>") != std::string::npos;
}

// `rospack find cartpole_qlearning`, "" when it fails. The command rather than roslib's
// ros::package::getPath: linking roslib loaded librospack, libpython3.11 and Boost into every run
// (7 of the 27 libraries it loaded; about 9 ms of CPU before main), for a look-up that nearly
// every run skips.
std::string rospackFind()
{
  std::string path;
  if (FILE* out = ::popen("rospack find cartpole_qlearning 2>/dev/null", "r"))
  {
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, out) != nullptr)
      path += buffer;
    if (::pclose(out) != 0)
      path.clear();
  }
  while (!path.empty() && (path.back() == '\n' || path.back() == '\r'))
    path.pop_back();
  return path;
}

std::string lookUpPackage()
{
  // rospack crawls every folder under the package path before it answers (Debian's adds
  // /usr/share: hundreds of folders, 0.1-0.3 s, most of a run to solved). The package is nearly
  // always at the top of the first entry (a workspace's src/cartpole_qlearning, or the entry
  // itself), which is where rospack's crawl would find it first too: looked for there; anywhere
  // else (deeper, or in a later entry, where an earlier entry may hold it deeper), rospack finds it.
  if (const char* path = std::getenv("ROS_PACKAGE_PATH"))
  {
    std::istringstream entries(path);
    std::string first;
    while (first.empty() && std::getline(entries, first, ':'))
    {
    }
    if (!first.empty())
    {
      if (isThisPackage(first))
        return first;
      if (isThisPackage(std::filesystem::path(first) / "cartpole_qlearning"))
        return (std::filesystem::path(first) / "cartpole_qlearning").string();
    }
  }
  return rospackFind();
}
}  // namespace

std::string packagePath()
{
  static const std::string path = lookUpPackage();
  return path;
}

std::optional<HeadlessSetup> readHeadlessSetup(const HeadlessOptions& options)
{
  HeadlessSetup setup;
  setup.table_dir = defaultTableDirectory(options.name_space);
  setup.config_path = options.config_path;
  if (options.evaluating() && setup.config_path.empty())
  {
    // A table alone is enough: it carries the configuration that trained it.
    try
    {
      const std::string path = tablePath(setup.table_dir, options.evaluate_path);
      const TableConfig own = tableConfig(loadTable(setup.table_dir, options.evaluate_path), path);
      setup.config = own.config;
      // Wide starts and perturbations were training's devices (robust.yaml starts in +-0.25, past
      // the 12 degrees that end an episode): the evaluation's starts are CartPole-v1's and its
      // physics unperturbed, as evaluate.launch's sim without a config. --config sets others.
      setup.config.start_state_bound = TrainingConfig().start_state_bound;
      setup.config.perturbations = PerturbationParams();
      setup.config_origin = "the table's own configuration (" + path + ")";
      setup.config_warning = own.defaults_used;
    }
    catch (const FileError& e)
    {
      std::cerr << "train_headless: --evaluate " << options.evaluate_path << ": " << e.what() << "\n";
      return std::nullopt;
    }
  }
  else if (setup.config_path.empty())
  {
    const std::string share = packagePath();
    if (share.empty())
    {
      std::cerr << "train_headless: package cartpole_qlearning not found (source devel/setup.bash) "
                   "and no --config given\n";
      return std::nullopt;
    }
    setup.config_path = share + "/config/cartpole.yaml";
  }
  if (!setup.config_path.empty())
  {
    try
    {
      const auto source = loadYamlParameters(setup.config_path);
      refuseUnknownSections(*source);
      setup.config = readTrainingConfig(*source);
      setup.config_origin = setup.config_path;
    }
    catch (const ConfigError& e)
    {
      std::cerr << "train_headless: " << e.what() << "\n";
      return std::nullopt;
    }
  }
  // An evaluation's episodes are its own length; a suite's cases, the suite's; the Control Suite's
  // tasks', unless told, their 1,000 steps (the score is their sum).
  if (options.evaluating() && options.suite_path.empty() &&
      (options.max_steps_given || !isSuiteTask(setup.config.task.kind)))
    setup.config.task.max_episode_steps = static_cast<unsigned>(options.max_steps);
  if (options.max_episodes > 0)
    setup.config.limits.max_episodes = options.max_episodes;
  const bool replay = !options.replay_path.empty();
  if ((options.trace || replay) && setup.config.agent.features == FeatureKind::Tiles)
  {
    std::cerr << "train_headless: " << (options.trace ? "--trace" : "--replay")
              << " shows one table row per state: it needs learning/features bins (" << setup.config_path
              << " has tiles)\n";
    return std::nullopt;
  }
  if (!saveStaysInTableFolder(setup.table_dir, options.save_path))
    return std::nullopt;
  return setup;
}

bool saveStaysInTableFolder(const std::string& table_dir, const std::string& save_path)
{
  // A relative --save must stay in the table folder, as over a service: said before any work.
  if (save_path.empty() || save_path.front() == '/')
    return true;
  try
  {
    relativePathUnder(table_dir, save_path);
  }
  catch (const FileError& e)
  {
    std::cerr << "train_headless: --save " << save_path << " is not allowed (" << e.what() << ")\n";
    return false;
  }
  return true;
}

bool printLog(const LogLines& log, bool quiet)
{
  bool error = false;
  for (const LogLine& line : log)
  {
    error = error || line.level == LogLine::Level::Error;
    if (line.level == LogLine::Level::Info)
    {
      if (!quiet)
        std::printf("%s\n", line.text.c_str());
    }
    else
    {
      std::fflush(stdout);
      std::fprintf(stderr, "train_headless: %s\n", line.text.c_str());
    }
  }
  return error;
}

// Tables as the command line names them (TableStore's rule): an absolute path is the user's own
// file, a relative one lies under the table folder.
void saveTable(const QTable& table, const std::string& table_dir, const std::string& path)
{
  TableStore(table_dir, "", AbsolutePaths::AreTheUsersFiles).save(table, path);
}

std::string tablePath(const std::string& table_dir, const std::string& path)
{
  return TableStore(table_dir, "", AbsolutePaths::AreTheUsersFiles).resolve(path);
}

QTable loadTable(const std::string& table_dir, const std::string& path)
{
  return TableStore(table_dir, "", AbsolutePaths::AreTheUsersFiles).load(path);
}

}  // namespace cartpole_qlearning
