// The YAML adapter of the config layer: a config file, a suite file, or YAML text in a test, read
// as slash-separated keys; and the writer of a table's trained_with.
#include "cartpole_qlearning/io/yaml_parameters.h"
#include "cartpole_qlearning/io/number_text.h"
#include "cartpole_qlearning/io/yaml_load.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
std::vector<std::string> splitKey(const std::string& key)
{
  std::vector<std::string> parts;
  std::stringstream in(key);
  std::string part;
  while (std::getline(in, part, '/'))
    parts.push_back(part);
  return parts;
}

class YamlParameters : public ParameterSource
{
public:
  YamlParameters(YAML::Node root, std::string origin, std::string folder)
    : root_(std::move(root)), origin_(std::move(origin)), folder_(std::move(folder))
  {
  }

  bool get(const std::string& key, double& value) const override
  {
    return scalar(key, value, "a number");
  }
  bool get(const std::string& key, std::int64_t& value) const override
  {
    return scalar(key, value, "a whole number");
  }
  bool get(const std::string& key, bool& value) const override
  {
    return scalar(key, value, "true or false");
  }
  bool get(const std::string& key, std::string& value) const override
  {
    return scalar(key, value, "a string");
  }
  bool get(const std::string& key, std::vector<double>& value) const override
  {
    const YAML::Node node = find(key);
    if (!node)
      return false;
    if (!node.IsSequence())
      throw ConfigError(origin_ + ": " + key + " must be a list of numbers");
    value.clear();
    for (std::size_t i = 0; i < node.size(); ++i)
    {
      try
      {
        value.push_back(node[i].as<double>());
      }
      catch (const YAML::Exception&)
      {
        throw ConfigError(origin_ + ": " + key + "[" + std::to_string(i) + "] = '" + text(node[i]) +
                          "' is not allowed (must be a number)");
      }
    }
    return true;
  }

  bool get(const std::string& key, std::vector<std::string>& value) const override
  {
    const YAML::Node node = find(key);
    if (!node)
      return false;
    if (!node.IsSequence())
      throw ConfigError(origin_ + ": " + key + " must be a list of strings");
    value.clear();
    for (std::size_t i = 0; i < node.size(); ++i)
    {
      if (!node[i].IsScalar())
        throw ConfigError(origin_ + ": " + key + "[" + std::to_string(i) + "] = '" + text(node[i]) +
                          "' is not allowed (must be a string)");
      value.push_back(node[i].Scalar());
    }
    return true;
  }

  bool getEntries(const std::string& key, std::vector<std::unique_ptr<ParameterSource>>& entries) const override
  {
    const YAML::Node node = find(key);
    if (!node)
      return false;
    if (!node.IsSequence())
      throw ConfigError(origin_ + ": " + key + " must be a list");
    entries.clear();
    for (std::size_t i = 0; i < node.size(); ++i)
    {
      if (node[i].IsMap())
        entries.push_back(
            std::make_unique<YamlParameters>(node[i], origin_ + ": " + key + "[" + std::to_string(i) + "]", folder_));
      else
        entries.push_back(nullptr);
    }
    return true;
  }

  std::vector<std::string> keysUnder(const std::string& section) const override
  {
    std::vector<std::string> keys;
    const YAML::Node node = find(section);
    if (node)
      collect(node, section, keys);
    return keys;
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
  YAML::Node find(const std::string& key) const
  {
    // reset() rebinds; plain assignment between yaml-cpp nodes would overwrite the tree itself.
    YAML::Node node;
    node.reset(root_);
    for (const std::string& part : splitKey(key))
    {
      if (part.empty())
        continue;
      if (!node.IsMap())
        return YAML::Node(YAML::NodeType::Undefined);
      const YAML::Node& parent = node;
      const YAML::Node child = parent[part];  // const lookup: does not insert the key
      if (!child)
        return child;
      node.reset(child);
    }
    return node;
  }

  template <typename T>
  bool scalar(const std::string& key, T& value, const char* expected) const
  {
    const YAML::Node node = find(key);
    if (!node)
      return false;
    try
    {
      if (!node.IsScalar())
        throw YAML::Exception(YAML::Mark::null_mark(), "not a scalar");
      value = node.as<T>();
    }
    catch (const YAML::Exception&)
    {
      throw ConfigError(origin_ + ": " + key + " = '" + text(node) + "' is not allowed (must be " + expected + ")");
    }
    return true;
  }

  static std::string text(const YAML::Node& node)
  {
    if (node.IsScalar())
      return node.Scalar();
    YAML::Emitter out;
    out << YAML::Flow << node;
    return out.c_str();
  }

  void collect(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& keys) const
  {
    if (!node.IsMap())
    {
      keys.push_back(prefix);
      return;
    }
    for (const auto& entry : node)
    {
      // A key that is not a plain scalar (a list, a map, a null) names no parameter (found by
      // test/fuzz/config_fuzzer.cpp: it used to escape as a YAML exception).
      if (!entry.first.IsScalar())
        throw ConfigError(origin_ + ": a key under '" + (prefix.empty() ? "/" : prefix) + "' is not a plain name");
      collect(entry.second, (prefix.empty() ? "" : prefix + "/") + entry.first.Scalar(), keys);
    }
  }

  YAML::Node root_;
  std::string origin_;
  std::string folder_;
};
}  // namespace

namespace
{
YAML::Node parsed(const std::string& text, const std::string& origin)
{
  try
  {
    return loadYaml(text);
  }
  catch (const YAML::Exception& e)
  {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
}
}  // namespace

std::unique_ptr<ParameterSource> parseYamlParameters(const std::string& text, const std::string& origin,
                                                     const std::string& folder)
{
  YAML::Node root = parsed(text, origin);
  if (root.IsNull())
    root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap())
    throw ConfigError(origin + ": must be a YAML mapping of sections (physics, task, learning, training)");
  return std::make_unique<YamlParameters>(root, origin, folder);
}

std::unique_ptr<ParameterSource> parseYamlMap(const std::string& text, const std::string& origin,
                                              const std::string& folder, const std::string& root_rule)
{
  const YAML::Node root = parsed(text, origin);
  if (!root.IsMap())
    throw ConfigError(origin + ": " + root_rule);
  return std::make_unique<YamlParameters>(root, origin, folder);
}

std::unique_ptr<ParameterSource> loadYamlParameters(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
    throw ConfigError(path + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  return parseYamlParameters(text.str(), path, configFolder(path));
}

std::string configFolder(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash + (slash == 0));
}

namespace
{
// Opens and closes the maps that the keys' paths name, in the order the keys come.
class YamlSink : public ParameterSink
{
public:
  void number(const std::string& key, double value) override
  {
    at(key) << shortestText(value);
  }
  void whole(const std::string& key, std::uint64_t value) override
  {
    at(key) << value;
  }
  void flag(const std::string& key, bool value) override
  {
    at(key) << value;
  }
  void word(const std::string& key, const std::string& value) override
  {
    at(key) << value;
  }
  void text(const std::string& key, const std::string& value) override
  {
    at(key) << YAML::DoubleQuoted << value;
  }
  void numbers(const std::string& key, const std::vector<double>& values) override
  {
    YAML::Emitter& out = at(key);
    out << YAML::Flow << YAML::BeginSeq;
    for (const double value : values)
      out << shortestText(value);
    out << YAML::EndSeq;
  }
  void texts(const std::string& key, const std::vector<std::string>& values) override
  {
    YAML::Emitter& out = at(key);
    out << YAML::Flow << YAML::BeginSeq;
    for (const std::string& value : values)
      out << YAML::DoubleQuoted << value;
    out << YAML::EndSeq;
  }

  std::string finish()
  {
    while (!open_.empty())
      close();
    out_ << YAML::EndMap;
    return std::string(out_.c_str()) + "\n";
  }

  YamlSink()
  {
    out_ << YAML::BeginMap;
  }

private:
  // The emitter, ready for the value of `key`.
  YAML::Emitter& at(const std::string& key)
  {
    std::vector<std::string> parts = splitKey(key);
    const std::string name = parts.back();
    parts.pop_back();
    std::size_t common = 0;
    while (common < open_.size() && common < parts.size() && open_[common] == parts[common])
      ++common;
    while (open_.size() > common)
      close();
    for (std::size_t i = common; i < parts.size(); ++i)
    {
      out_ << YAML::Key << parts[i] << YAML::Value << YAML::BeginMap;
      open_.push_back(parts[i]);
    }
    out_ << YAML::Key << name << YAML::Value;
    return out_;
  }

  void close()
  {
    out_ << YAML::EndMap;
    open_.pop_back();
  }

  YAML::Emitter out_;
  std::vector<std::string> open_;  // the maps open, outermost first
};
}  // namespace

std::string yamlText(const std::function<void(ParameterSink& sink)>& write)
{
  YamlSink sink;
  write(sink);
  return sink.finish();
}

}  // namespace cartpole_qlearning
