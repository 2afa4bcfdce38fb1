// The nodes' private parameters (~mode, ~q_table_dir, ~robots, ... for the controller; ~mode,
// ~lockstep_timeout, ... for the sim), read and checked by the core through a ParameterSource,
// so that every rule is a unit test with YAML text. The node passes in only what needs ROS.
#pragma once

#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/protocol/robot_interface.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The namespaces of `count` robots relative to the learner's (~robots: N): its own ("") for one,
// robot_0 ... robot_<count-1> for more. train.launch robots:=N starts its sims there
// (launch/include/robot_sims.launch spells the rule again: roslaunch cannot call this), and
// train_headless --robots N names its robots so.
std::vector<std::string> robotNamespaces(std::size_t count);

// What the application around the learner needs (run_application.h): the controller node fills
// it from its private parameters, train_headless from its command line.
// An evaluation's episodes are this many steps long unless it is told otherwise (~max_steps,
// train_headless --max-steps) or poses as a suite case (the suite's): never the training
// configuration's task/max_episode_steps, which is how long training's episodes were.
constexpr unsigned kEvaluationMaxSteps = 500;

struct RunSettings
{
  bool learning = true;  // ~mode: train (true) or evaluate or control (greedy, no learning)
  // ~mode control: the table drives the robot with no episodes' step limit, no verdict and no
  // learning; a fall commands 0 until a start, and ControlMeter says how it goes.
  bool control = false;
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
  // (train_headless's command line, the node's parameters); false: it must lie inside q_table_dir.
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
  // false (train_headless --no-run-folder): no run folder at all (no checkpoints, record, curve of
  // its own or save on shutdown); a solved run's only save is the default table.
  bool run_folder = true;
  bool trace = false;  // log every update and the table at each episode end
  // train_headless's run: what is said names its options, not the node's parameters, services and
  // launch arguments (a command-line user has none of them).
  bool command_line = false;
  // Where a relative training/suite is looked for, in order (the package's config/; for
  // train_headless first its --config's folder). None: a relative suite is not found.
  std::vector<std::string> suite_folders;
};

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

// The command a robot takes: ~command_type, ~command_joint (robot.cart_joint unless given),
// ~command_index and ~command_size; read alike by the controller and the command watchdog.
// Throws ConfigError naming a bad one.
void readRobotCommand(SectionReader& priv, RobotInterfaceParams& robot);

// Reads the shared sections from `shared` and the private parameters from `priv`. Throws
// ConfigError naming the parameter, its value and what is allowed, on a bad value or an
// unknown private key. An evaluation of a table (~mode evaluate, ~load_on_start) with no
// configuration in `shared` runs with the table's own (table_config.h); one given beside it is
// checked against the table when the run starts (RunApplication::start).
ControllerSettings readControllerSettings(const ParameterSource& shared, const ParameterSource& priv,
                                          const ControllerContext& context);

enum class SimMode
{
  Realtime,  // steps on a wall timer, holding the last command
  Lockstep   // steps when the command answering the pending state arrives
};

struct SimSettings
{
  CartPoleParams physics;           // the shared physics section
  EngineParams engine;              // physics/engine and, for a MuJoCo model, its model, joints and actuator
  double start_state_bound = 0.05;  // physics/start_state_bound
  SimMode mode = SimMode::Realtime;
  std::uint64_t seed = 0;
  double command_timeout = 0.5;   // [s] realtime: an older command counts as zero
  double lockstep_timeout = 0.5;  // [s] lockstep: republish the state when unanswered this long
  double effort_limit = 10.0;     // [N] <= physics.force_mag, which is its default
  bool publish_clock = false;     // lockstep only: drive /clock (one lockstep instance per master)
  bool publish_tf = true;
  double tf_rate = 30.0;  // [Hz] lockstep: TF at most this often (wall clock)
  double track_y = 0.0;   // [m] where the track lies along world y (several robots side by side)
  std::string world_frame = "world";
  // "": the engine's bodies (cartBody(), poleBody(): the equations' cart and pole, a model's own).
  std::string cart_frame;
  std::string pole_frame;
  // What a real cart-pole does (the shared perturbations section, as train_headless reads it from
  // its config), or the suite case's when ~suite_case names one.
  PerturbationParams perturbations;
  // ~suite and ~suite_case: the sim poses as this case of the suite file (its physics, start
  // region and perturbations over the shared ones; its seed unless ~seed is given). "": none.
  std::string suite;
  std::string suite_case;
  // Posing as another cart-pole (docs/your_own_cartpole.md): its joint names (by default a MuJoCo
  // model's cart_joint and pole_joint, else cart_joint and pole_joint), offsets and signs
  // (~cart_joint, ~pole_joint, ~cart_zero, ~cart_sign, ~pole_upright, ~pole_angle_sign), whole turns
  // added to the pole's reading (~pole_turns) and whether velocities are published.
  // (~effort_sign too: -1, a robot whose + effort pushes the cart toward -x.)
  RobotInterfaceParams pose;
  // [s] ~publish_period: joint_states every this much sim time (physics/tau by default); the physics
  // still steps every tau (SampledPhysics).
  double publish_period = 0.02;
  // ~group_effort_index: the cart's slot in the std_msgs/Float64MultiArray commands on group_effort
  // (a JointGroupEffortController's).
  std::uint64_t group_effort_index = 0;
  int pole_turns = 0;
  bool publish_velocities = true;
};

// Reads the physics and perturbations sections from `shared` and the sim's private parameters
// from `priv` (loading ~suite when ~suite_case is set); throws ConfigError as
// readControllerSettings does.
SimSettings readSimSettings(const ParameterSource& shared, const ParameterSource& priv);

// The controller's first line: what it does, with which table, serving whom ("training, seed 0,
// 72 states x 2 actions, tables under DIR; serving ROBOTS; resets by ~cartpole_sim/reset").
std::string controllerStartText(const ControllerSettings& settings, const QTable& table,
                                const std::string& table_directory, const std::string& served);

}  // namespace cartpole_qlearning
