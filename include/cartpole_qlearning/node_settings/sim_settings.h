// The sim node's private parameters (~mode, ~lockstep_timeout, ~tf_rate, ...), read and checked
// without ROS through a ParameterSource (test/node_settings/ runs every rule with YAML text).
#pragma once

#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/protocol/robot_interface.h"
#include "cartpole_qlearning/simulation/perturbations.h"

#include <cstdint>
#include <string>

namespace cartpole_qlearning
{
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
  // Where a random start (the first state, an empty reset) is drawn: the shared task section's
  // (CartPole-v1's +-start_state_bound, the Suite's swing-ups hanging), as train_headless draws its
  // episodes' starts.
  StartDistribution start = StartDistribution::uniform(0.05);
  TaskKind task = TaskKind::CartPoleV1;
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

}  // namespace cartpole_qlearning
