#include "cartpole_qlearning/application/training_run.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <locale>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
constexpr const char* kFormatName = "cartpole_qlearning/run";
constexpr int kVersion = 1;

[[noreturn]] void refuse(const std::string& what)
{
  throw FileError("run record: " + what);
}

std::string timeText(std::time_t when, const char* format)
{
  std::tm local{};
  ::localtime_r(&when, &local);
  char text[64];
  std::strftime(text, sizeof text, format, &local);
  return text;
}
}  // namespace

std::string localTimeText(std::time_t when)
{
  return timeText(when, "%Y-%m-%d %H:%M:%S");
}

std::string runFolderName(std::time_t started, const std::string& name_space, std::uint64_t seed)
{
  std::string ns;
  for (char c : name_space)
    ns += c == '/' ? '_' : c;
  while (!ns.empty() && ns.front() == '_')
    ns.erase(ns.begin());
  if (ns.empty())
    ns = "root";
  return std::string(kRunsFolder) + "/" + timeText(started, "%Y-%m-%d_%H-%M-%S") + "_" + ns + "_seed" +
         std::to_string(seed);
}

std::string formatRunRecord(const RunRecord& record)
{
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::Comment("A training run of cartpole_qlearning: its checkpoint table is " + std::string(kRunTableFile) +
                       " beside this file.");
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kFormatName;
  out << YAML::Key << "version" << YAML::Value << kVersion;
  out << YAML::Key << "run_id" << YAML::Value << YAML::DoubleQuoted << record.run_id;
  out << YAML::Key << "namespace" << YAML::Value << YAML::DoubleQuoted << record.name_space;
  out << YAML::Key << "seed" << YAML::Value << record.seed;
  out << YAML::Key << "started" << YAML::Value << YAML::DoubleQuoted << record.started;
  out << YAML::Key << "episodes" << YAML::Value << record.episodes;
  out << YAML::Key << "steps" << YAML::Value << record.steps;
  out << YAML::Key << "recent_returns" << YAML::Value << YAML::Flow << record.recent_returns;
  out << YAML::Key << "finished" << YAML::Value << YAML::DoubleQuoted << record.finished;
  if (!record.robustness.empty())
    out << YAML::Key << "robustness" << YAML::Value << YAML::DoubleQuoted << record.robustness;
  if (record.best_episode > 0)
  {
    out << YAML::Key << "best" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "table" << YAML::Value << kRunBestTableFile;
    out << YAML::Key << "episode" << YAML::Value << record.best_episode;
    out << YAML::Key << "worst_balanced" << YAML::Value << record.best_worst_balanced;
    out << YAML::Key << "robustness" << YAML::Value << YAML::DoubleQuoted << record.best_robustness;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

RunRecord parseRunRecord(const std::string& text)
{
  RunRecord record;
  try
  {
    const YAML::Node root = YAML::Load(text);
    if (!root.IsMap() || !root["format"] || root["format"].as<std::string>() != kFormatName)
      refuse("not a run record (format is not '" + std::string(kFormatName) + "')");
    if (!root["version"] || root["version"].as<int>() != kVersion)
      refuse("version is not " + std::to_string(kVersion));
    const auto get = [&](const char* key) {
      const YAML::Node node = root[key];
      if (!node)
        refuse(std::string("missing key '") + key + "'");
      return node;
    };
    record.run_id = get("run_id").as<std::string>();
    record.name_space = get("namespace").as<std::string>();
    record.seed = get("seed").as<std::uint64_t>();
    record.started = get("started").as<std::string>();
    record.episodes = get("episodes").as<std::uint64_t>();
    record.steps = get("steps").as<std::uint64_t>();
    record.recent_returns = get("recent_returns").as<std::vector<double>>();
    record.finished = get("finished").as<std::string>();
    if (root["robustness"])
      record.robustness = root["robustness"].as<std::string>();
    if (const YAML::Node best = root["best"])
    {
      if (!best.IsMap() || !best["episode"] || !best["worst_balanced"] || !best["robustness"])
        refuse("best must be a map with episode, worst_balanced and robustness");
      record.best_episode = best["episode"].as<std::uint64_t>();
      record.best_worst_balanced = best["worst_balanced"].as<std::uint64_t>();
      record.best_robustness = best["robustness"].as<std::string>();
    }
  }
  catch (const YAML::Exception& e)
  {
    refuse(std::string("not readable: ") + e.what());
  }
  for (double r : record.recent_returns)
  {
    if (!std::isfinite(r))
      refuse("a recent return is not finite");
  }
  if (record.finished != "" && record.finished != "solved" && record.finished != "suite_passed" &&
      record.finished != "max_episodes")
    refuse("finished is '" + record.finished + "' (allowed: '', 'solved', 'suite_passed', 'max_episodes')");
  return record;
}

}  // namespace cartpole_qlearning
