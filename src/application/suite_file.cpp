#include "cartpole_qlearning/application/suite_file.h"

#include "cartpole_qlearning/io/yaml_parameters.h"
#include "cartpole_qlearning/simulation/engine_registry.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
// A case's keys, named for messages as "FILE: case NAME" once its name is known (the file's entry
// says "FILE: cases[i]"): the same messages as a config file's sections, prefixed by the case.
class CaseSource : public ParameterSource
{
public:
  CaseSource(const ParameterSource& entry, std::string origin, std::string folder)
    : entry_(entry), origin_(std::move(origin)), folder_(std::move(folder))
  {
  }
  bool get(const std::string& key, double& value) const override
  {
    return renamed([&] { return entry_.get(key, value); });
  }
  bool get(const std::string& key, std::int64_t& value) const override
  {
    return renamed([&] { return entry_.get(key, value); });
  }
  bool get(const std::string& key, bool& value) const override
  {
    return renamed([&] { return entry_.get(key, value); });
  }
  bool get(const std::string& key, std::string& value) const override
  {
    return renamed([&] { return entry_.get(key, value); });
  }
  bool get(const std::string& key, std::vector<double>& value) const override
  {
    return renamed([&] { return entry_.get(key, value); });
  }
  bool get(const std::string& key, std::vector<std::string>& value) const override
  {
    return renamed([&] { return entry_.get(key, value); });
  }
  std::vector<std::string> keysUnder(const std::string& section) const override
  {
    return renamed([&] { return entry_.keysUnder(section); });
  }
  std::string origin() const override
  {
    return origin_;
  }
  std::string folder() const override
  {
    return folder_;
  }

private:
  // The entry's own messages start with its origin: this one's instead.
  template <typename Get>
  auto renamed(Get get) const -> decltype(get())
  {
    try
    {
      return get();
    }
    catch (const ConfigError& e)
    {
      const std::string message = e.what();
      const std::string prefix = entry_.origin() + ": ";
      if (message.compare(0, prefix.size(), prefix) != 0)
        throw;
      throw ConfigError(origin_ + ": " + message.substr(prefix.size()));
    }
  }

  const ParameterSource& entry_;
  std::string origin_;
  std::string folder_;
};

template <typename Number>
ConfigKey<RobustnessSuite> wholeNumberKey(const std::string& name, Number RobustnessSuite::*member, std::int64_t min,
                                          std::int64_t max)
{
  return {name, "int",
          [=](SectionReader& reader, RobustnessSuite& suite) {
            std::int64_t value = static_cast<std::int64_t>(suite.*member);
            reader.read(name, value);
            if (value < min || value > max)
              reader.fail(name, std::to_string(value),
                          "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
            suite.*member = static_cast<Number>(value);
          },
          nullptr};
}

// Starts in +-this: a finite number >= 0, said as it is written.
void readBound(SectionReader& reader, double& bound)
{
  const std::string name = "start_state_bound";
  double value = bound;
  try
  {
    reader.read(name, value);
  }
  catch (const ConfigError&)
  {
    std::string scalar;
    if (!reader.source().get(reader.key(name), scalar))  // not one value either: throws naming the key
      throw;
    value = -1.0;
  }
  if (!(std::isfinite(value) && value >= 0.0))
  {
    std::string text;
    reader.source().get(reader.key(name), text);
    reader.fail(name, "'" + text + "'", "must be a finite number >= 0");
  }
  bound = value;
}

const char* const kCasesRule = "cases must be a list of cases, each with a name";

// The file's top level; the cases are read apart (readCase), over the configuration.
const ConfigSection<RobustnessSuite>& suiteSection()
{
  static const ConfigSection<RobustnessSuite> section{
      "",
      {wholeNumberKey("episodes", &RobustnessSuite::episodes, 1, 1000000),
       wholeNumberKey("seed", &RobustnessSuite::seed, 0, std::numeric_limits<long long>::max()),
       wholeNumberKey("max_episode_steps", &RobustnessSuite::max_episode_steps, 1, std::numeric_limits<int>::max()),
       {"start_state_bound", "double",
        [](SectionReader& reader, RobustnessSuite& suite) { readBound(reader, suite.start_state_bound); }, nullptr},
       {"cases", "list of maps",
        [](SectionReader& reader, RobustnessSuite&) {
          reader.know("cases");
          std::vector<std::unique_ptr<ParameterSource>> entries;
          bool listed = false;
          try
          {
            listed = reader.source().getEntries("cases", entries);
          }
          catch (const ConfigError&)
          {
          }
          if (!listed || entries.empty())
            throw ConfigError(reader.source().origin() + ": " + kCasesRule);
        },
        nullptr}},
      nullptr};
  return section;
}

SuiteCase readCase(const ParameterSource* entry, const std::string& where, const RobustnessSuite& suite,
                   const TrainingConfig& base, std::set<std::string>& names)
{
  SuiteCase c;
  try
  {
    if (entry == nullptr || !entry->get("name", c.name) || c.name.empty())
      throw ConfigError("");
  }
  catch (const ConfigError&)
  {
    throw ConfigError(where + " must be a map with a name");
  }
  if (!names.insert(c.name).second)
    throw ConfigError(where + ": the name " + c.name + " is used twice");
  const CaseSource source(*entry, suite.origin + ": case " + c.name, configFolder(suite.origin));
  for (const std::string& key : source.keysUnder(""))
  {
    const std::string top = key.substr(0, key.find('/'));
    if (top != "name" && top != "pass" && top != "physics" && top != "perturbations")
      throw ConfigError(source.origin() + ": unknown key " + top + " (known keys: name, pass, physics, perturbations)");
  }
  std::int64_t pass = static_cast<std::int64_t>(c.pass);
  if (source.get("pass", pass) && (pass < 0 || static_cast<std::uint64_t>(pass) > suite.episodes))
    throw ConfigError(source.describe("pass") + " = " + std::to_string(pass) + " is not allowed (must be in [0, " +
                      std::to_string(suite.episodes) + "])");
  c.pass = static_cast<std::uint64_t>(pass);
  // The case's sections, read by the configuration's own readers: the same keys, checks and messages.
  // (A case's model is relative to the suite file's folder.)
  c.physics = base.physics;
  c.engine = base.engine;
  c.start_state_bound = suite.start_state_bound;
  readPhysics(source, c.physics, c.start_state_bound, c.engine);
  c.perturbations = readPerturbations(source);
  checkPerturbationsFitEngine(source, c.engine, c.perturbations);
  return c;
}

RobustnessSuite readRobustnessSuite(const ParameterSource& source, const TrainingConfig& base)
{
  RobustnessSuite suite;
  suite.origin = source.origin();
  suiteSection().read(source, suite);
  std::vector<std::unique_ptr<ParameterSource>> entries;
  source.getEntries("cases", entries);
  std::set<std::string> names;
  for (std::size_t i = 0; i < entries.size(); ++i)
  {
    const std::string where = suite.origin + ": cases[" + std::to_string(i) + "]";
    suite.cases.push_back(readCase(entries[i].get(), where, suite, base, names));
  }
  return suite;
}

const char* const kRootRule = "must be a map with the keys episodes, seed and cases";
}  // namespace

RobustnessSuite parseRobustnessSuite(const std::string& yaml, const std::string& origin, const TrainingConfig& base)
{
  return readRobustnessSuite(*parseYamlMap(yaml, origin, configFolder(origin), kRootRule), base);
}

RobustnessSuite loadRobustnessSuite(const std::string& path, const TrainingConfig& base)
{
  std::ifstream in(path);
  if (!in)
    throw ConfigError(path + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return parseRobustnessSuite(text.str(), path, base);
}

bool episodesRunInAnyOrder(const SuiteCase& suite_case)
{
  return engineOf(suite_case.engine).episodes_independent && !suite_case.perturbations.drawsWhileStepping();
}
}  // namespace cartpole_qlearning
