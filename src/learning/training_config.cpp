#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/io/number_text.h"

#include "cartpole_qlearning/simulation/engine_registry.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace cartpole_qlearning
{
namespace
{
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

// A file key of the engine in use (a model): ${VARIABLES} expanded, relative to the config's folder,
// required.
void resolveFile(SectionReader& reader, const EngineKey& key, const std::string& engine_name, std::string& path)
{
  if (reader.has(key.name))
  {
    const std::string given = path;
    path = expandEnvironment(given, [&](const std::string& variable) {
      reader.fail(key.name, "'" + given + "'",
                  "the environment variable " + variable + " is not set: set it, or give the path itself");
    });
    if (path.empty())
      reader.fail(key.name, "''", "must name " + key.file);
    if (path.front() != '/' && !reader.source().folder().empty())
      path = reader.source().folder() + "/" + path;
  }
  if (path.empty())
    reader.fail(key.name, "''", "physics/engine " + engine_name + " needs " + key.file);
}

bool takes(const EngineDescription& engine, const std::string& name)
{
  return std::any_of(engine.keys.begin(), engine.keys.end(),
                     [&name](const EngineKey& mine) { return mine.name == name; });
}

// physics/engine: one the registry knows; every other engine's keys are refused beside it.
ConfigKey<PhysicsSection> engineKey()
{
  return {"engine", "string: the physics engine (engine_registry.h)",
          [](SectionReader& reader, PhysicsSection& s) {
            reader.read("engine", s.engine.name);
            const EngineDescription* own = nullptr;
            try
            {
              own = &engineOf(s.engine);
            }
            catch (const std::invalid_argument& e)
            {
              reader.fail("engine", "'" + s.engine.name + "'", e.what());
            }
            for (const EngineDescription& other : engineDescriptions())
              for (const EngineKey& key : other.keys)
                if (!takes(*own, key.name) && reader.has(key.name))
                  throw ConfigError(reader.source().describe(reader.key(key.name)) +
                                    " is not allowed with physics/engine " + own->name + " (" +
                                    (own->foreign_keys_note.empty() ? other.own_keys_note : own->foreign_keys_note) +
                                    ")");
          },
          [](SectionWriter& writer, const PhysicsSection& s) { writer.word("engine", s.engine.name); }};
}

// A key an engine alone takes: read whatever the engine (its default stays unless given), written
// beside its engine only.
ConfigKey<PhysicsSection> engineOwnKey(const EngineKey& key)
{
  using P = PhysicsSection;
  ConfigKey<P> own;
  if (key.number != nullptr)
    own = plainKey<P>(
        key.name, "double", [key](auto& p) -> auto& { return p.physics.*key.number; });
  else if (key.choice != nullptr)
    own = nameKey<P>(
        key.name, "string", [key](auto& p) -> auto& { return p.physics.*key.choice; }, integratorFromString);
  else
  {
    own = plainKey<P>(
        key.name, key.file.empty() ? "string" : "string, path: " + key.file, [key](auto& p) -> auto& {
          return p.engine.*key.text;
        });
    own.read = [key](SectionReader& reader, P& p) {
      reader.read(key.name, p.engine.*key.text);
      const EngineDescription& engine = engineOf(p.engine);
      if (!key.file.empty() && takes(engine, key.name))
        resolveFile(reader, key, engine.name, p.engine.*key.text);
    };
  }
  own.write = [key, write = own.write](SectionWriter& writer, const P& p) {
    // (A key omitted at its default: the tables of configs from before it stay as they were.)
    const bool omitted =
        key.omitted_at_default && key.number != nullptr && p.physics.*key.number == CartPoleParams().*key.number;
    if (takes(engineOf(p.engine), key.name) && !omitted)
      write(writer, p);
  };
  return own;
}

// One number of steps, or [low, high]: drawn per episode.
void readSteps(SectionReader& reader, const std::string& name, unsigned& low, unsigned& high)
{
  const ParameterSource& source = reader.source();
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

void readFactors(SectionReader& reader, const std::string& name, ScaleRange& range)
{
  const ParameterSource& source = reader.source();
  std::vector<double> bounds;
  reader.know(name);
  if (!source.get(reader.key(name), bounds))
    return;
  if (bounds.size() != 2)
    reader.fail(name, SectionReader::listText(bounds), "must list 2 factors: [low, high]");
  range.low = bounds[0];
  range.high = bounds[1];
}

ConfigKey<PerturbationParams> perturbationKey(const PerturbationKey& key)
{
  using Form = PerturbationKey::Form;
  switch (key.form)
  {
    case Form::Steps:
      return {
          key.name, "int or [low, high], steps",
          [key](SectionReader& reader, PerturbationParams& p) { readSteps(reader, key.name, p.*key.low, p.*key.high); },
          [key](SectionWriter& writer, const PerturbationParams& p) {
            if (p.*key.low == p.*key.high)
              writer.write(key.name, p.*key.low);
            else
              writer.write(key.name, std::vector<double>{double(p.*key.low), double(p.*key.high)});
          }};
    case Form::Dimensions:
      return {key.name, "4 doubles",
              [key](SectionReader& reader, PerturbationParams& p) {
                readDimensions(reader, key.name, p.*key.dimensions, false);
              },
              [key](SectionWriter& writer, const PerturbationParams& p) { writer.write(key.name, p.*key.dimensions); }};
    case Form::Factors:
      return {key.name, "[low, high] factors",
              [key](SectionReader& reader, PerturbationParams& p) { readFactors(reader, key.name, p.*key.factors); },
              [key](SectionWriter& writer, const PerturbationParams& p) {
                writer.write(key.name, std::vector<double>{(p.*key.factors).low, (p.*key.factors).high});
              }};
    case Form::Number:
      break;
  }
  return plainKey<PerturbationParams>(
      key.name, "double", [key](auto& p) -> auto& { return p.*key.number; });
}

// The five sections' names, in the file's order.
const std::vector<std::string>& sectionNames()
{
  static const std::vector<std::string> names{physicsSection().name, perturbationsSection().name, taskSection().name,
                                              learningSection().name, trainingSection().name};
  return names;
}
}  // namespace

const ConfigSection<PhysicsSection>& physicsSection()
{
  static const ConfigSection<PhysicsSection> section = [] {
    ConfigSection<PhysicsSection> s{"physics", {engineKey()}, [](const SectionReader& reader, const PhysicsSection& p) {
                                      reader.check(p.physics.validate());
                                      if (!(std::isfinite(p.start_state_bound) && p.start_state_bound >= 0.0))
                                        reader.fail("start_state_bound", std::to_string(p.start_state_bound),
                                                    "must be finite and >= 0");
                                    }};
    for (const EngineDescription& engine : engineDescriptions())
      for (const EngineKey& key : engine.keys)
        if (std::none_of(s.keys.begin(), s.keys.end(), [&key](const auto& k) { return k.name == key.name; }))
          s.keys.push_back(engineOwnKey(key));
    const auto physics = [](auto member) {
      return [member](auto& p) -> auto&
      {
        return p.physics.*member;
      };
    };
    s.keys.push_back(plainKey<PhysicsSection>("force_mag", "double, N: commands are clamped to +-this",
                                              physics(&CartPoleParams::force_mag)));
    s.keys.push_back(plainKey<PhysicsSection>("tau", "double, s: the step", physics(&CartPoleParams::tau)));
    s.keys.push_back(plainKey<PhysicsSection>(
        "start_state_bound", "double: random starts are uniform in +-this",
        [](auto& p) -> auto& { return p.start_state_bound; }));
    return s;
  }();
  return section;
}

const ConfigSection<PerturbationParams>& perturbationsSection()
{
  static const ConfigSection<PerturbationParams> section = [] {
    ConfigSection<PerturbationParams> s{
        "perturbations", {}, [](const SectionReader& reader, const PerturbationParams& p) {
          reader.check(p.validate());
        }};
    for (const PerturbationKey& key : perturbationKeys())
      s.keys.push_back(perturbationKey(key));
    return s;
  }();
  return section;
}

std::vector<std::string> configKeys()
{
  std::vector<std::string> keys;
  for (const std::vector<std::string>& section :
       {physicsSection().keyNames(), perturbationsSection().keyNames(), taskSection().keyNames(),
        learningSection().keyNames(), trainingSection().keyNames()})
    keys.insert(keys.end(), section.begin(), section.end());
  return keys;
}

void refuseUnknownSections(const ParameterSource& source)
{
  const std::vector<std::string>& sections = sectionNames();
  std::string list;
  for (std::size_t i = 0; i < sections.size(); ++i)
    list += (i == 0 ? "" : i + 1 == sections.size() ? " and " : ", ") + sections[i];
  for (const std::string& key : source.keysUnder(""))
  {
    const std::string section = key.substr(0, key.find('/'));
    if (std::find(sections.begin(), sections.end(), section) == sections.end() || key == section)
      throw ConfigError(source.origin() + ": unknown key " + key + " (the file holds the sections " + list + ")");
  }
}

void readPhysics(const ParameterSource& source, CartPoleParams& physics, double& start_state_bound,
                 EngineParams& engine)
{
  PhysicsSection s{physics, engine, start_state_bound};
  physicsSection().read(source, s);
  physics = s.physics;
  engine = s.engine;
  start_state_bound = s.start_state_bound;
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
  PerturbationParams p;
  perturbationsSection().read(source, p);
  return p;
}

TaskParams readTask(const ParameterSource& source)
{
  TaskParams task;
  taskSection().read(source, task);
  return task;
}

AgentParams readAgent(const ParameterSource& source)
{
  AgentParams agent;
  learningSection().read(source, agent);
  return agent;
}

TrainingLimits readLimits(const ParameterSource& source)
{
  TrainingLimits limits;
  trainingSection().read(source, limits);
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
  for (const std::string& section : sectionNames())
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

std::string trainingConfigText(const TrainingConfig& config)
{
  return yamlText([&config](ParameterSink& sink) {
    physicsSection().write(sink, PhysicsSection{config.physics, config.engine, config.start_state_bound});
    perturbationsSection().write(sink, config.perturbations);
    taskSection().write(sink, config.task);
    learningSection().write(sink, config.agent);
    trainingSection().write(sink, config.limits);
  });
}

}  // namespace cartpole_qlearning
