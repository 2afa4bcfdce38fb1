// The controller node's private parameters (~mode, ~q_table_dir, ~robots, ...), read and checked
// without ROS through a ParameterSource, so that every rule is a unit test with YAML text
// (test/node_settings/). The node passes in only what needs ROS (ControllerContext).
#pragma once

#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"
#include "cartpole_qlearning/protocol/robot_interface.h"

#include <functional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
struct ControllerSettings
{
  TrainingConfig training;  // the shared sections, with ~stop_when_solved and ~max_episodes applied
  RunSettings run;
  bool shutdown_when_finished = true;  // end the launch (or the node) when done
  double sim_timeout = 2.0;            // [s] wall: a robot silent this long is said to be gone
  // [s] wall: efforts go out only this long after a fresh, valid state was decided on (0: off).
  double freshness_timeout = 0.1;
  // ~robot_lockstep: the robot is a sim in lockstep, which steps only when a command answers its
  // state and holds none: the freshness guard is off by default, and may be in mode control.
  bool robot_lockstep = false;
  // What the parameters allow but a robot's owner should hear, once, as the controller starts
  // (evaluate and control: values far from the table's step, no ~max_effort).
  std::vector<std::string> warnings;
  std::string reset_service = "cartpole_sim/reset";  // "": a robot that cannot be reset on command
  std::vector<std::string> robots{""};               // namespaces relative to the learner's
  bool sync = true;                                  // several robots: served in lockstep rounds
  ControllerProtocolParams protocol;                 // reset_service, start_region, limits
  RobotInterfaceParams robot;                        // joints, offsets, command type, decision period
  // ~reset_service_type: what ~reset_service is
  std::string reset_service_type = "cartpole_qlearning/Reset";
  // The robots are cartpole_sims: ~reset_service is a cartpole_sim's (reset or reset_simulation).
  // A robot's driver otherwise: what the silence warning asks about.
  bool simulated = true;
};

// What only ROS knows, handed in by the node.
struct ControllerContext
{
  std::string name_space = "/cartpole";  // the learner's namespace (the default table folder's name)
  std::string home;                      // $HOME, for "~/" in paths ("": none)
  bool shutdown_by_default = true;       // ~shutdown_when_finished's default (a nodelet: false)
  // "" for a valid relative ROS name, else why it is not one (ros::names::validate; unset: any
  // name passes).
  std::function<std::string(const std::string&)> name_error;
  // Private keys read by other means (dynamic_reconfigure's fields, ~run/...): not unknown.
  std::vector<std::string> other_keys;
  std::vector<std::string> suite_folders;  // RunSettings::suite_folders (the package's config/)
};

// Reads the shared sections from `shared` and the private parameters from `priv`. Throws
// ConfigError naming the parameter, its value and what is allowed, on a bad value or an
// unknown private key. An evaluation of a table (~mode evaluate, ~load_on_start) with no
// configuration in `shared` runs with the table's own (table_config.h); one given beside it is
// checked against the table when the run starts (RunApplication::start).
ControllerSettings readControllerSettings(const ParameterSource& shared, const ParameterSource& priv,
                                          const ControllerContext& context);

// The controller's first line: what it does, with which table, serving whom ("training, seed 0,
// 72 states x 2 actions, tables under DIR; serving ROBOTS; resets by ~cartpole_sim/reset").
std::string controllerStartText(const ControllerSettings& settings, const QTable& table,
                                const std::string& table_directory, const std::string& served);

}  // namespace cartpole_qlearning
