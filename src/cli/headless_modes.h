// train_headless's modes, one file each: training (from scratch, from a table, or on from a run
// folder), a greedy evaluation, a robustness suite, a replay of transitions, a table's policy, the
// mean of tables.
// Each prints what it says and returns the exit status; the main only dispatches.
#pragma once

#include "headless_options.h"

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/learning/training_config.h"

#include <optional>
#include <string>

namespace cartpole_qlearning
{
// What every mode but --policy runs with: the configuration, where it came from, the table folder.
struct HeadlessSetup
{
  TrainingConfig config;       // --max-episodes applied; evaluating, --max-steps as task/max_episode_steps
  std::string config_path;     // "": the table's own configuration
  std::string config_origin;   // as messages name the configuration (RunSettings::config_origin)
  std::string config_warning;  // what the table's own leaves to the defaults (RunSettings::config_warning)
  std::string table_dir;
};

// The configuration (--config; else, evaluating, the table's own; else the package's), checked
// against the options (--trace and --replay need bins, a relative --save stays in the table
// folder): nullopt after saying why.
std::optional<HeadlessSetup> readHeadlessSetup(const HeadlessOptions& options);
// The package's folder ("" when ROS cannot find it).
std::string packagePath();

// What the application says: information on stdout (none with --quiet), the rest on stderr.
// Returns whether an error was said.
bool printLog(const LogLines& log, bool quiet);

// Tables by the services' path rule (an absolute path is the user's own, a relative one under the
// table folder): the one place train_headless reads and writes them.
QTable loadTable(const std::string& table_dir, const std::string& path);
void saveTable(const QTable& table, const std::string& table_dir, const std::string& path);
// Where loadTable and saveTable find `path`: made absolute.
std::string tablePath(const std::string& table_dir, const std::string& path);
// Whether a relative --save stays in the table folder (an absolute one is the user's): false after
// saying why.
bool saveStaysInTableFolder(const std::string& table_dir, const std::string& save_path);

int trainMode(const HeadlessOptions& options, const HeadlessSetup& setup);     // train_mode.cpp
int evaluateMode(const HeadlessOptions& options, const HeadlessSetup& setup);  // evaluate_mode.cpp
int suiteMode(const HeadlessOptions& options, const HeadlessSetup& setup);     // suite_mode.cpp
int replayMode(const HeadlessOptions& options, const HeadlessSetup& setup);    // replay_mode.cpp
int policyMode(const HeadlessOptions& options);                                // policy_mode.cpp
int averageMode(const HeadlessOptions& options);                               // average_mode.cpp

}  // namespace cartpole_qlearning
