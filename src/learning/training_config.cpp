#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/io/number_text.h"

#include "cartpole_qlearning/simulation/engine_registry.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace cartpole_qlearning
{
namespace
{
template <typename Enum, typename Parse>
void readEnum(SectionReader& reader, const std::string& name, Enum& value, Parse parse)
{
  std::string text = toString(value);
  reader.read(name, text);
  try
  {
    value = parse(text);
  }
  catch (const std::invalid_argument& e)
  {
    reader.fail(name, "'" + text + "'", e.what());
  }
}

void readSchedule(SectionReader& reader, const std::string& name, ScheduleParams& schedule)
{
  readEnum(reader, name + "/schedule", schedule.type, scheduleTypeFromString);
  reader.read(name + "/start", schedule.start);
  reader.read(name + "/min", schedule.min);
  reader.read(name + "/decay_episodes", schedule.decay_episodes);
  reader.read(name + "/decay_rate", schedule.decay_rate);
  reader.read(name + "/log_divisor", schedule.log_divisor);
}

// The text with each ${NAME} replaced by the environment variable NAME; on_missing(NAME) is called
// (and must throw) for one that is not set.
template <typename OnMissing>
std::string expandEnvironment(const std::string& text, OnMissing on_missing)
{
  std::string out;
  std::size_t at = 0;
  for (std::size_t open = text.find("${"); open != std::string::npos; open = text.find("${", at))
  {
    const std::size_t close = text.find('}', open);
    if (close == std::string::npos)
      break;
    const std::string name = text.substr(open + 2, close - open - 2);
    const char* value = std::getenv(name.c_str());
    if (value == nullptr)
      on_missing(name);
    out += text.substr(at, open - at) + (value ? value : "");
    at = close + 1;
  }
  return out + text.substr(at);
}

// The engine's file keys (a model): ${VARIABLES} expanded, relative to the config's folder, required.
void readEngineFiles(const ParameterSource& source, SectionReader& reader, const EngineDescription& own,
                     EngineParams& engine)
{
  for (const EngineKey& key : own.keys)
  {
    if (key.file.empty())
      continue;
    std::string& path = engine.*key.text;
    if (!source.keysUnder(reader.key(key.name)).empty())
    {
      const std::string given = path;
      path = expandEnvironment(given, [&](const std::string& variable) {
        reader.fail(key.name, "'" + given + "'",
                    "the environment variable " + variable + " is not set: set it, or give the path itself");
      });
      if (path.empty())
        reader.fail(key.name, "''", "must name " + key.file);
      if (path.front() != '/' && !source.folder().empty())
        path = source.folder() + "/" + path;
    }
    if (path.empty())
      reader.fail(key.name, "''", "physics/engine " + own.name + " needs " + key.file);
  }
}

// One number of steps, or [low, high]: drawn per episode.
void readSteps(const ParameterSource& source, SectionReader& reader, const std::string& name, unsigned& low,
               unsigned& high)
{
  reader.know(name);
  const char* const allowed = "must be a whole number of steps in [0, 1000], or [low, high] of them";
  std::int64_t steps = 0;
  bool single = false;
  try
  {
    single = source.get(reader.key(name), steps);
  }
  catch (const ConfigError&)
  {
    std::vector<double> delay;
    source.get(reader.key(name), delay);  // not a list either: throws naming the key
    if (delay.size() != 2 || delay[0] != std::floor(delay[0]) || delay[1] != std::floor(delay[1]) || delay[0] < 0 ||
        delay[1] < delay[0] || delay[1] > 1000)
      reader.fail(name, SectionReader::listText(delay), allowed);
    low = static_cast<unsigned>(delay[0]);
    high = static_cast<unsigned>(delay[1]);
  }
  if (single)
  {
    if (steps < 0 || steps > 1000)
      reader.fail(name, std::to_string(steps), allowed);
    low = high = static_cast<unsigned>(steps);
  }
}

void readFactors(const ParameterSource& source, SectionReader& reader, const std::string& name, ScaleRange& range)
{
  std::vector<double> bounds;
  reader.know(name);
  if (!source.get(reader.key(name), bounds))
    return;
  if (bounds.size() != 2)
    reader.fail(name, SectionReader::listText(bounds), "must list 2 factors: [low, high]");
  range.low = bounds[0];
  range.high = bounds[1];
}
}  // namespace

void refuseUnknownSections(const ParameterSource& source)
{
  static const std::set<std::string> sections{"physics", "perturbations", "task", "learning", "training"};
  for (const std::string& key : source.keysUnder(""))
  {
    const std::string section = key.substr(0, key.find('/'));
    if (sections.count(section) == 0 || key == section)
      throw ConfigError(source.origin() + ": unknown key " + key +
                        " (the file holds the sections physics, perturbations, task, learning and training)");
  }
}

void readPhysics(const ParameterSource& source, CartPoleParams& physics, double& start_state_bound,
                 EngineParams& engine)
{
  SectionReader reader(source, "physics");
  reader.read("engine", engine.name);
  const EngineDescription* found = nullptr;
  try
  {
    found = &engineOf(engine);
  }
  catch (const std::invalid_argument& e)
  {
    reader.fail("engine", "'" + engine.name + "'", e.what());
  }
  const EngineDescription& own = *found;
  // Every engine's texts, then the keys of the others refused (before any number is read), then
  // every engine's numbers: an engine's keys keep their defaults unless given.
  for (const EngineDescription& other : engineDescriptions())
    for (const EngineKey& key : other.keys)
      if (key.text != nullptr)
        reader.read(key.name, engine.*key.text);
  for (const EngineDescription& other : engineDescriptions())
  {
    for (const EngineKey& key : other.keys)
    {
      const bool owned = std::any_of(own.keys.begin(), own.keys.end(),
                                     [&key](const EngineKey& mine) { return mine.name == key.name; });
      if (!owned && !source.keysUnder(reader.key(key.name)).empty())
        throw ConfigError(source.describe(reader.key(key.name)) + " is not allowed with physics/engine " + own.name +
                          " (" + (own.foreign_keys_note.empty() ? other.own_keys_note : own.foreign_keys_note) + ")");
    }
  }
  readEngineFiles(source, reader, own, engine);
  for (const EngineDescription& other : engineDescriptions())
  {
    for (const EngineKey& key : other.keys)
    {
      if (key.number != nullptr)
        reader.read(key.name, physics.*key.number);
      else if (key.choice != nullptr)
        readEnum(reader, key.name, physics.*key.choice, integratorFromString);
    }
  }
  reader.read("force_mag", physics.force_mag);
  reader.read("tau", physics.tau);
  reader.read("start_state_bound", start_state_bound);
  reader.refuseUnknown();
  reader.check(physics.validate());
  if (!(std::isfinite(start_state_bound) && start_state_bound >= 0.0))
    reader.fail("start_state_bound", std::to_string(start_state_bound), "must be finite and >= 0");
}

void checkPerturbationsFitEngine(const ParameterSource& source, const EngineParams& engine,
                                 const PerturbationParams& perturbations)
{
  if (!engineOf(engine).scales_half_length && perturbations.half_length.varies())
    throw ConfigError(source.describe("perturbations/half_length") + " is not allowed with physics/engine " +
                      engine.name + " (a model's pole is its geometry: scale it in the model)");
}

PerturbationParams readPerturbations(const ParameterSource& source)
{
  using Form = PerturbationKey::Form;
  PerturbationParams p;
  SectionReader reader(source, "perturbations");
  for (const PerturbationKey& key : perturbationKeys())
  {
    switch (key.form)
    {
      case Form::Steps:
        readSteps(source, reader, key.name, p.*key.low, p.*key.high);
        break;
      case Form::Dimensions:
        reader.readDimensions(key.name, p.*key.dimensions, false);
        break;
      case Form::Factors:
        readFactors(source, reader, key.name, p.*key.factors);
        break;
      case Form::Number:
        reader.read(key.name, p.*key.number);
        break;
    }
  }
  reader.refuseUnknown();
  reader.check(p.validate());
  return p;
}

TaskParams readTask(const ParameterSource& source)
{
  TaskParams task;
  SectionReader reader(source, "task");
  readEnum(reader, "kind", task.kind, taskKindFromString);
  if (isSuiteTask(task.kind))
  {
    task.max_episode_steps = kSuiteEpisodeSteps;
    for (const char* key : {"x_threshold", "theta_threshold_deg", "reward", "solved_reward", "x_cost", "x_dot_cost"})
      if (!source.keysUnder(reader.key(key)).empty())
        throw ConfigError(
            source.describe(reader.key(key)) + " is not allowed with task/kind " + toString(task.kind) +
            " (CartPole-v1's: the Suite's tasks never end on the cart or the angle, and score by their own reward)");
  }
  reader.read("x_threshold", task.x_threshold);
  reader.read("theta_threshold_deg", task.theta_threshold_deg);
  reader.read("max_episode_steps", task.max_episode_steps, 1, std::numeric_limits<int>::max());
  // Trained on the Suite's whole episodes (an evaluation or a robot may run others).
  if (isSuiteTask(task.kind) && task.max_episode_steps != kSuiteEpisodeSteps)
    reader.fail("max_episode_steps", std::to_string(task.max_episode_steps),
                "the Suite's episodes are " + std::to_string(kSuiteEpisodeSteps) + " steps (task/kind " +
                    toString(task.kind) + ")");
  readEnum(reader, "reward", task.reward, rewardSchemeFromString);
  std::string solved_reward;
  reader.read("solved_reward", solved_reward);
  if (!solved_reward.empty())
  {
    try
    {
      task.solved_reward = rewardSchemeFromString(solved_reward);
    }
    catch (const std::invalid_argument& e)
    {
      reader.fail("solved_reward", "'" + solved_reward + "'", e.what());
    }
  }
  reader.read("x_cost", task.x_cost);
  reader.read("x_dot_cost", task.x_dot_cost);
  reader.read("solved_mean_return", task.solved_mean_return);
  reader.read("solved_window", task.solved_window, 1, 1000000);
  reader.refuseUnknown();
  reader.check(task.validate());
  return task;
}

AgentParams readAgent(const ParameterSource& source)
{
  AgentParams agent;
  SectionReader reader(source, "learning");
  reader.read("gamma", agent.gamma);
  reader.read("actions", agent.actions);
  readEnum(reader, "features", agent.features, featureKindFromString);
  reader.readDimensions("bins", agent.discretiser.bins, true);
  reader.read("tilings", agent.tilings, 1, kMaxTilings);
  reader.readDimensions("tiles", agent.tiles, true);
  reader.read("previous_action", agent.previous_action);
  reader.readDimensions("lower_bounds", agent.discretiser.lower, false);
  reader.readDimensions("upper_bounds", agent.discretiser.upper, false);
  readSchedule(reader, "epsilon", agent.epsilon);
  readSchedule(reader, "alpha", agent.alpha);
  reader.read("state_names", agent.state_names);
  reader.refuseUnknown();
  reader.check(agent.validate());
  return agent;
}

TrainingLimits readLimits(const ParameterSource& source)
{
  TrainingLimits limits;
  SectionReader reader(source, "training");
  reader.read("max_episodes", limits.max_episodes, 1);
  reader.read("stop_when_solved", limits.stop_when_solved);
  reader.read("progress_every", limits.progress_every, 0);
  reader.read("suite", limits.suite);
  if (limits.suite.empty())
    reader.fail("suite", "''", "a suite file, or none");
  reader.read("suite_every", limits.suite_every, 0);
  reader.read("best_every", limits.best_every, 0);
  // Looked for at evaluations only: its episodes must be some of the suite's.
  if (limits.best_every > 0 && (limits.suite_every == 0 || limits.best_every % limits.suite_every != 0))
    reader.fail("best_every", std::to_string(limits.best_every),
                "0, or a multiple of training/suite_every (" + std::to_string(limits.suite_every) +
                    "): the best is looked for at evaluations of the suite");
  std::string until = limits.until == TrainUntil::Solved ? "solved" : "suite_passes";
  reader.readChoice("until", until, {"solved", "suite_passes"});
  limits.until = until == "solved" ? TrainUntil::Solved : TrainUntil::SuitePasses;
  if (limits.until == TrainUntil::SuitePasses && (limits.suite_every == 0 || limits.suite == "none"))
    reader.fail("until", "suite_passes",
                "needs training/suite_every > 0 and a training/suite: the suite is evaluated during training");
  reader.refuseUnknown();
  return limits;
}

TrainingConfig readTrainingConfig(const ParameterSource& source)
{
  TrainingConfig config;
  readPhysics(source, config.physics, config.start_state_bound, config.engine);
  config.perturbations = readPerturbations(source);
  checkPerturbationsFitEngine(source, config.engine, config.perturbations);
  config.task = readTask(source);
  if (isSuiteTask(config.task.kind) && config.physics.tau != kSuiteTau)
    throw ConfigError(source.describe("physics/tau") + " = " + exactText(config.physics.tau) +
                      " is not allowed with task/kind " + toString(config.task.kind) +
                      " (the Suite's steps are 0.01 s)");
  config.agent = readAgent(source);
  config.limits = readLimits(source);
  for (const double effort : config.agent.actions)
  {
    if (std::fabs(effort) > config.physics.force_mag)
      throw ConfigError(source.origin() + ": learning/actions contains " + std::to_string(effort) +
                        ", which is not allowed (|effort| must be <= physics/force_mag = " +
                        std::to_string(config.physics.force_mag) + ")");
  }
  return config;
}

bool holdsTrainingConfig(const ParameterSource& source)
{
  for (const char* section : {"physics", "perturbations", "task", "learning", "training"})
  {
    if (!source.keysUnder(section).empty())
      return true;
  }
  return false;
}

std::string exactText(double value)
{
  return shortestText(value);
}

namespace
{

template <typename Container>
void emitNumbers(YAML::Emitter& out, const Container& values)
{
  out << YAML::Flow << YAML::BeginSeq;
  for (const auto value : values)
    out << exactText(static_cast<double>(value));
  out << YAML::EndSeq;
}

void emitSchedule(YAML::Emitter& out, const char* name, const ScheduleParams& schedule)
{
  out << YAML::Key << name << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "schedule" << YAML::Value << toString(schedule.type);
  for (const auto& [key, value] : {std::pair<const char*, double>{"start", schedule.start},
                                   {"min", schedule.min},
                                   {"decay_episodes", schedule.decay_episodes},
                                   {"decay_rate", schedule.decay_rate},
                                   {"log_divisor", schedule.log_divisor}})
    out << YAML::Key << key << YAML::Value << exactText(value);
  out << YAML::EndMap;
}

void emitNumber(YAML::Emitter& out, const char* key, double value)
{
  out << YAML::Key << key << YAML::Value << exactText(value);
}

// The physics section: only the keys the engine takes (readPhysics refuses the others beside it).
void emitPhysics(YAML::Emitter& out, const TrainingConfig& config)
{
  const CartPoleParams& physics = config.physics;
  const EngineParams& engine = config.engine;
  out << YAML::Key << "physics" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "engine" << YAML::Value << engine.name;
  for (const EngineKey& key : engineOf(engine).keys)
  {
    if (key.omitted_at_default && key.number != nullptr && physics.*key.number == CartPoleParams().*key.number)
      continue;
    if (key.number != nullptr)
      emitNumber(out, key.name.c_str(), physics.*key.number);
    else if (key.choice != nullptr)
      out << YAML::Key << key.name << YAML::Value << toString(physics.*key.choice);
    else
      out << YAML::Key << key.name << YAML::Value << YAML::DoubleQuoted << engine.*key.text;
  }
  emitNumber(out, "force_mag", physics.force_mag);
  emitNumber(out, "tau", physics.tau);
  emitNumber(out, "start_state_bound", config.start_state_bound);
  out << YAML::EndMap;
}

void emitPerturbations(YAML::Emitter& out, const PerturbationParams& p)
{
  out << YAML::Key << "perturbations" << YAML::Value << YAML::BeginMap;
  for (const PerturbationKey& key : perturbationKeys())
  {
    out << YAML::Key << key.name << YAML::Value;
    switch (key.form)
    {
      case PerturbationKey::Form::Steps:
        if (p.*key.low == p.*key.high)
          out << p.*key.low;
        else
          emitNumbers(out, std::array<unsigned, 2>{{p.*key.low, p.*key.high}});
        break;
      case PerturbationKey::Form::Dimensions:
        emitNumbers(out, p.*key.dimensions);
        break;
      case PerturbationKey::Form::Factors:
        emitNumbers(out, std::array<double, 2>{{(p.*key.factors).low, (p.*key.factors).high}});
        break;
      case PerturbationKey::Form::Number:
        out << exactText(p.*key.number);
        break;
    }
  }
  out << YAML::EndMap;
}
}  // namespace

std::string trainingConfigText(const TrainingConfig& config)
{
  YAML::Emitter out;
  out << YAML::BeginMap;

  emitPhysics(out, config);
  emitPerturbations(out, config.perturbations);

  const TaskParams& task = config.task;
  out << YAML::Key << "task" << YAML::Value << YAML::BeginMap;
  // The kind only when not the default, so that the tables of configs without it stay as they were;
  // the Suite's kinds end and score by their own rules (readTask refuses CartPole-v1's keys beside them).
  if (isSuiteTask(task.kind))
  {
    out << YAML::Key << "kind" << YAML::Value << toString(task.kind);
  }
  else
  {
    emitNumber(out, "x_threshold", task.x_threshold);
    emitNumber(out, "theta_threshold_deg", task.theta_threshold_deg);
  }
  out << YAML::Key << "max_episode_steps" << YAML::Value << task.max_episode_steps;
  if (!isSuiteTask(task.kind))
    out << YAML::Key << "reward" << YAML::Value << toString(task.reward);
  // Only when set, so that the tables of configs without them stay as they were.
  if (task.solved_reward)
    out << YAML::Key << "solved_reward" << YAML::Value << toString(*task.solved_reward);
  if (task.reward == RewardScheme::AliveQuadratic)
  {
    emitNumber(out, "x_cost", task.x_cost);
    emitNumber(out, "x_dot_cost", task.x_dot_cost);
  }
  emitNumber(out, "solved_mean_return", task.solved_mean_return);
  out << YAML::Key << "solved_window" << YAML::Value << task.solved_window;
  out << YAML::EndMap;

  const AgentParams& agent = config.agent;
  out << YAML::Key << "learning" << YAML::Value << YAML::BeginMap;
  emitNumber(out, "gamma", agent.gamma);
  out << YAML::Key << "actions" << YAML::Value;
  emitNumbers(out, agent.actions);
  out << YAML::Key << "features" << YAML::Value << toString(agent.features);
  out << YAML::Key << "bins" << YAML::Value;
  emitNumbers(out, agent.discretiser.bins);
  out << YAML::Key << "tilings" << YAML::Value << agent.tilings;
  out << YAML::Key << "tiles" << YAML::Value;
  emitNumbers(out, agent.tiles);
  out << YAML::Key << "previous_action" << YAML::Value << agent.previous_action;
  out << YAML::Key << "lower_bounds" << YAML::Value;
  emitNumbers(out, agent.discretiser.lower);
  out << YAML::Key << "upper_bounds" << YAML::Value;
  emitNumbers(out, agent.discretiser.upper);
  emitSchedule(out, "epsilon", agent.epsilon);
  emitSchedule(out, "alpha", agent.alpha);
  if (!agent.state_names.empty())
  {
    out << YAML::Key << "state_names" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const std::string& name : agent.state_names)
      out << YAML::DoubleQuoted << name;
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;

  const TrainingLimits& limits = config.limits;
  out << YAML::Key << "training" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "max_episodes" << YAML::Value << limits.max_episodes;
  out << YAML::Key << "stop_when_solved" << YAML::Value << limits.stop_when_solved;
  out << YAML::Key << "progress_every" << YAML::Value << limits.progress_every;
  out << YAML::Key << "suite" << YAML::Value << YAML::DoubleQuoted << limits.suite;
  out << YAML::Key << "suite_every" << YAML::Value << limits.suite_every;
  out << YAML::Key << "best_every" << YAML::Value << limits.best_every;
  out << YAML::Key << "until" << YAML::Value << (limits.until == TrainUntil::Solved ? "solved" : "suite_passes");
  out << YAML::EndMap;

  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace cartpole_qlearning
