// train_headless's command line as values: the options it takes, the rules for which go together,
// and the run settings they make. Parsing is a pure function (no files, no process), so that every
// option and every rule is a unit test (test/cli/headless_options_test.cpp).
#pragma once

#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/learning/policy_grid.h"

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The options as typed, checked one by one (a path is not looked at here).
struct HeadlessOptions
{
  bool help = false;  // --help or -h: the usage, nothing else (what follows it is not read)

  std::string config_path;  // "": the package's config/cartpole.yaml
  std::optional<std::uint64_t> seed;
  std::uint64_t robots = 1;
  std::string name_space = "/cartpole";  // always absolute
  std::uint64_t max_episodes = 0;        // 0: training/max_episodes

  std::string save_path;
  std::string load_path;
  std::string resume_folder;
  std::uint64_t checkpoint_every = RunSettings().checkpoint_every;
  bool checkpoint_given = false;
  bool no_run_folder = false;
  std::string stats_csv_path;
  bool quiet = false;
  bool print_returns = false;
  bool trace = false;
  std::uint64_t greedy_check = 0;  // training: N greedy episodes after each episode until all balance (0: none)

  std::string evaluate_path;
  std::uint64_t evaluation_episodes = 100;
  bool episodes_given = false;
  std::uint64_t max_steps = kEvaluationMaxSteps;  // --evaluate: an episode's length (never the config's)
  bool max_steps_given = false;
  // --evaluate (with or without --suite): decide for the state predicted this many steps ahead.
  std::uint64_t predict_delay = 0;
  bool predict_delay_given = false;
  std::string suite_path;

  std::string replay_path;

  // --average TABLE, once per table: their mean is written to --save.
  std::vector<std::string> average_paths;

  std::string policy_path;
  std::uint64_t grid_points = PolicyGridParams().points;
  std::string axes = "theta,theta_dot";
  std::string policy_at;
  std::string previous = "none";

  // Every option in the order typed (values left out): what a policy is drawn without is named
  // as the user typed it.
  std::vector<std::string> typed;

  bool evaluating() const
  {
    return !evaluate_path.empty();
  }
};

// The command line read: its options, or why it is refused.
struct HeadlessCommandLine
{
  HeadlessOptions options;
  // "" when the options can be used; else what train_headless prints after "train_headless: "
  // before it exits with 2.
  std::string error;
  bool usage_after_error = false;  // an unknown or incomplete option: the usage follows
};

// An option as a rule sees it: its name and whether the command line has it in effect (some are
// in effect only with some values: --robots 1 is the default, --checkpoint-every 0 writes none).
struct RuleOption
{
  const char* name;
  bool (*given)(const HeadlessOptions&);
};

// Which options go together. Checked in the table's order; the first broken rule is the refusal.
struct OptionRule
{
  enum class Kind
  {
    Requires,  // any of `others` needs `option`: "OTHERS: WHY"
    Excludes,  // `option` with any of `others` is refused: "OTHER with OPTION: WHY"
    OneOf,     // `option` and `others` (one) are refused together: "OPTION and OTHER: WHY"
    Alone,     // `option` with any typed option but `others`: "TYPED with OPTION: WHY"
  };
  Kind kind;
  RuleOption option;
  std::vector<RuleOption> others;
  std::string why;
};

const std::vector<OptionRule>& headlessOptionRules();

// args: the arguments after the program's name.
HeadlessCommandLine parseHeadlessOptions(const std::vector<std::string>& args);

// The settings the core's messages point at, named as train_headless's users type them (--save,
// --stats-csv, ...).
SettingNames headlessSettingNames();

// The settings the controller reads from its private parameters, made from the command line.
// table_dir: the namespace's table folder; config_path: the configuration in use (a relative
// training/suite is looked for beside it first); package_path: the package's folder ("": not found).
RunSettings headlessRunSettings(const HeadlessOptions& options, std::uint64_t seed, const std::string& table_dir,
                                const std::string& config_path, const std::string& package_path);

// A whole number >= 0 as typed (digits only): false when `text` is not one.
bool parseCount(const std::string& text, std::uint64_t& value);

// The usage: every option, what it does and the exit codes.
void printHeadlessUsage(std::ostream& out);

}  // namespace cartpole_qlearning
