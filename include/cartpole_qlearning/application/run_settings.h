// What the application around the learner needs to run (run_application.h): the controller node
// fills it from its private parameters (node_settings/controller_settings.h), train_headless from
// its command line (src/cli). The core takes values only; how a user sets each is the front end's
// (RunSettings::names).
#pragma once

#include "cartpole_qlearning/common/setting_names.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The namespaces of `count` robots relative to the learner's: its own ("") for one,
// robot_0 ... robot_<count-1> for more. The launch files start their sims there
// (launch/include/robot_sims.launch spells the rule again: roslaunch cannot call this), and
// train_headless names its robots so.
std::vector<std::string> robotNamespaces(std::size_t count);

// An evaluation's episodes are this many steps long unless it is told otherwise or poses as a
// suite case (the suite's): never the training configuration's task/max_episode_steps, which is
// how long training's episodes were.
constexpr unsigned kEvaluationMaxSteps = 500;

enum class RunMode
{
  Train,     // learning, in episodes, until the training's limits
  Evaluate,  // greedy, no learning, episodes of a step limit and a verdict
  // Greedy, no learning, with no episodes' step limit and no verdict: the table drives the robot;
  // a fall commands 0 until a start, and ControlMeter says how it goes.
  Control
};

struct RunSettings
{
  RunMode mode = RunMode::Train;
  bool learning() const
  {
    return mode == RunMode::Train;
  }
  bool controlling() const
  {
    return mode == RunMode::Control;
  }
  double report_every = 10.0;  // [s] control: a report this often (robot time)
  // Evaluate and control: decide for the state the table's model predicts this many steps ahead,
  // for a robot known to carry commands out that many steps late (DelayPredictor); 0: for the
  // state observed.
  unsigned predict_delay_steps = 0;
  // [s] control: the most robot time one decision counts (ControlMeter's max_gap): the freshness
  // bound, five decision periods or five steps, the longest.
  double control_max_gap = 0.1;
  std::uint64_t seed = 0;
  std::string name_space = "/cartpole";  // the learner's namespace: its table folder by default, its run folders' names
  // Tables are read and written under this folder (a relative path there; one that escapes it is
  // refused). "~/" at its start is the user's home.
  std::string q_table_dir;
  std::string q_table_path = "q_table.yaml";  // the default table, relative to q_table_dir ("": none)
  std::string load_on_start;                  // a table to start from ("": none)
  // An absolute q_table_path or load_on_start is the user's own, followed as the shell would
  // (the command line, the node's parameters); false: it must lie inside q_table_dir.
  bool own_absolute_paths = false;
  // "" the run's folder/episodes.csv (training; none when evaluating), "none" no file, else a
  // path (relative: under q_table_dir; absolute: the user's own).
  std::string stats_csv;
  std::string run_id;  // the launch's own id: a respawn finds its run by it
  // Where the training configuration came from, as messages name it ("config/robust.yaml",
  // "parameter server (/cartpole)", "the table's own configuration").
  std::string config_origin = "the configuration";
  // What the run takes from the defaults because its table does not say it (tableConfig's
  // defaults_used): said as a warning at the start. "": nothing.
  std::string config_warning;
  std::uint64_t evaluation_episodes = 10;  // evaluate: the verdict after this many episodes (0: never)
  // evaluate: what the robot poses as ("case one_step_late of .../robust_suite.yaml"; "": not
  // said) and the balanced episodes its verdict needs to pass.
  std::string evaluation_case;
  std::uint64_t evaluation_pass = 0;
  std::uint64_t checkpoint_every = 100;  // training: a checkpoint every this many episodes (0: none)
  bool save_on_shutdown = true;          // training: save into the run's folder when stopped early
  // false: no run folder at all (no checkpoints, record, curve of its own or save on shutdown); a
  // solved run's only save is the default table.
  bool run_folder = true;
  bool trace = false;  // log every update and the table at each episode end
  // How what is said names the settings: the node's parameters and services, or the command
  // line's options (a command-line user has none of the node's).
  SettingNames names;
  // Where a relative training/suite is looked for, in order (the package's config/; for
  // train_headless first its config's folder). None: a relative suite is not found.
  std::vector<std::string> suite_folders;
};

}  // namespace cartpole_qlearning
