#include "cartpole_qlearning/node_settings/sim_settings.h"

#include "settings_parts.h"

#include "cartpole_qlearning/node_settings/robot_settings.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
// ~suite and ~suite_case: a suite case's physics, start region and perturbations replace the
// shared ones, as train_headless runs a suite's case; its seed is the suite's unless ~seed is set.
void poseAsSuiteCase(const ParameterSource& source, SectionReader& priv, SimSettings& settings)
{
  TrainingConfig base;
  base.physics = settings.physics;
  base.start_state_bound = settings.start_state_bound;
  base.engine = settings.engine;
  const auto found = readSuiteCase(priv, base);
  if (!found)
    return;
  const auto& [suite, suite_case] = *found;
  settings.suite = suite.origin;
  settings.suite_case = suite_case.name;
  settings.physics = suite_case.physics;
  settings.engine = suite_case.engine;
  settings.start_state_bound = suite_case.start_state_bound;
  settings.perturbations = suite_case.perturbations;
  if (source.keysUnder("seed").empty())
    settings.seed = suite.seed;
}

// The sim's own noise keys gave way to the core's model, which train_headless shares: each is
// refused naming what replaced it.
void refuseFormerNoiseKeys(const ParameterSource& source, SectionReader& priv)
{
  for (const auto& [name, instead] :
       {std::pair<const char*, const char*>{"position_noise_std", "noise_std: [x, x_dot, theta, theta_dot]"},
        {"velocity_noise_std", "noise_std and noise_fraction: [x, x_dot, theta, theta_dot]"},
        {"effort_noise_std",
         "motor: [low, high] (the motor's strength per episode), push_probability and "
         "push_force"}})
  {
    if (source.keysUnder(name).empty())
      continue;
    std::string value;
    try
    {
      double number = 0.0;
      source.get(name, number);
      value = SectionReader::numberText(number);
    }
    catch (const ConfigError&)
    {
      value = anyValueText(source, name);
    }
    priv.fail(name, value,
              std::string("replaced by the shared perturbations section, as in config/cartpole.yaml: perturbations/") +
                  instead);
  }
}

// What the sim publishes and how: joint_states' period, the group command's slot, whole turns,
// velocities, /clock, TF and its frames.
void readPublishing(const ParameterSource& source, SectionReader& priv, SimSettings& settings)
{
  settings.publish_period = settings.physics.tau;
  priv.read("publish_period", settings.publish_period);
  // A stamp step of at least a microsecond; a second apart is no joint_states stream to pose as.
  if (!source.keysUnder("publish_period").empty() &&
      !(settings.publish_period >= 1e-6 && settings.publish_period <= 1.0))
    priv.fail("publish_period", SectionReader::numberText(settings.publish_period), "must be in [1e-06, 1] s");
  priv.read("group_effort_index", settings.group_effort_index, 0);
  std::int64_t turns = 0;
  priv.read("pole_turns", turns);
  if (turns < -1000 || turns > 1000)
    priv.fail("pole_turns", std::to_string(turns), "must be a whole number in [-1000, 1000]");
  settings.pole_turns = static_cast<int>(turns);
  priv.read("publish_velocities", settings.publish_velocities);
  priv.read("publish_clock", settings.publish_clock);
  priv.read("publish_tf", settings.publish_tf);
  priv.read("track_y", settings.track_y);
  if (!std::isfinite(settings.track_y))
    priv.fail("track_y", SectionReader::numberText(settings.track_y), "must be finite");
  for (const auto& [name, frame] : {std::pair<const char*, std::string*>{"world_frame", &settings.world_frame},
                                    {"cart_frame", &settings.cart_frame},
                                    {"pole_frame", &settings.pole_frame}})
  {
    priv.read(name, *frame);
    if (frame->empty() && !source.keysUnder(name).empty())
      priv.fail(name, "''", "frame names must not be empty");
  }
}
}  // namespace

SimSettings readSimSettings(const ParameterSource& shared, const ParameterSource& source)
{
  SimSettings settings;
  readPhysics(shared, settings.physics, settings.start_state_bound, settings.engine);

  // The same reader and checks as the shared sections; a key it does not know (a typo such as
  // lockstep_timout) stops the node instead of being ignored.
  SectionReader priv(source, "");
  std::string mode = "realtime";
  priv.readChoice("mode", mode, {"realtime", "lockstep"});
  settings.mode = mode == "lockstep" ? SimMode::Lockstep : SimMode::Realtime;
  priv.read("seed", settings.seed, 0);
  settings.perturbations = readPerturbations(shared);
  checkPerturbationsFitEngine(shared, settings.engine, settings.perturbations);
  poseAsSuiteCase(source, priv, settings);
  const TaskParams task = readTask(shared);
  settings.task = task.kind;
  settings.start = task.start(settings.start_state_bound);
  priv.readSeconds("command_timeout", settings.command_timeout, 0.0, 60.0, true);
  priv.readSeconds("lockstep_timeout", settings.lockstep_timeout, 0.0, 3600.0, true);
  priv.readAtLeast("tf_rate", settings.tf_rate, 0.0, true);
  settings.effort_limit = settings.physics.force_mag;
  priv.readAtLeast("effort_limit", settings.effort_limit, 0.0, true);
  if (settings.effort_limit > settings.physics.force_mag)
    priv.fail("effort_limit", SectionReader::numberText(settings.effort_limit),
              "must be <= physics/force_mag = " + SectionReader::numberText(settings.physics.force_mag));
  refuseFormerNoiseKeys(source, priv);
  useModelJoints(settings.engine, settings.pose);
  readRobotPose(priv, settings.pose);
  readPublishing(source, priv, settings);
  priv.refuseUnknown();
  if (settings.publish_clock && settings.mode != SimMode::Lockstep)
    priv.fail("publish_clock", "true", "only in lockstep mode: in realtime the wall clock is the clock");
  return settings;
}

}  // namespace cartpole_qlearning
