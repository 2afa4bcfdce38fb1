// The settings the core's messages point users at, by what they do. The core never spells how a
// user sets one: the nodes know them as private parameters, train_headless as options, so each
// front end hands the core a SettingNames that names them as its users type them
// (node_settings/node_setting_names.h, src/cli's headlessSettingNames()).
#pragma once

#include <functional>
#include <utility>
#include <string>

namespace cartpole_qlearning
{
enum class Setting
{
  LoadOnStart,        // the table a run starts from
  LoadOnStartOrigin,  // how a launch set that table, said after it when a start from it fails ("": not said)
  TablePath,          // the default table, where a solved run's table goes
  TableFolder,        // the folder tables are read and written under
  SaveService,        // how to save the table in use elsewhere while the run goes on ("": no such way)
  StatsCsv,           // the learning curve's file ("none": no curve)
  Seed,               // the run's seed
  StartRegion,        // where an episode starts without a reset service
  ResetService,       // the robot's reset service
  ResetServiceType,   // the type of that service
  DecisionPeriod,     // the time between two decisions
  StateTopic,         // the robot's joint_states topic
  CommandTimeout,     // the command watchdog's silence bound
  CurveViewer,        // the command that draws a learning curve as it grows (followed by the file)
  SuiteEvaluation,    // the command that runs a table through a suite, every episode of it
};

// Names a setting as a front end's users type it. Default: plain words (the core's own tests,
// a front end that has said nothing), never a parameter's or an option's name.
class SettingNames
{
public:
  using Namer = std::function<std::string(Setting)>;
  SettingNames() = default;
  explicit SettingNames(Namer namer) : namer_(std::move(namer)) {}
  std::string operator()(Setting setting) const;

private:
  Namer namer_;
};

// The plain words for a setting (what SettingNames says when no front end named it).
std::string plainSettingName(Setting setting);

}  // namespace cartpole_qlearning
