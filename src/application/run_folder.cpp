#include "cartpole_qlearning/application/run_folder.h"

#include "cartpole_qlearning/io/yaml_count.h"
#include "cartpole_qlearning/io/yaml_load.h"

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

unsigned long long count(std::uint64_t value)
{
  return static_cast<unsigned long long>(value);
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
    const YAML::Node root = loadYaml(text);
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
    record.seed = yamlCount(get("seed"));
    record.started = get("started").as<std::string>();
    record.episodes = yamlCount(get("episodes"));
    record.steps = yamlCount(get("steps"));
    record.recent_returns = get("recent_returns").as<std::vector<double>>();
    record.finished = get("finished").as<std::string>();
    if (root["robustness"])
      record.robustness = root["robustness"].as<std::string>();
    if (const YAML::Node best = root["best"])
    {
      if (!best.IsMap() || !best["episode"] || !best["worst_balanced"] || !best["robustness"])
        refuse("best must be a map with episode, worst_balanced and robustness");
      record.best_episode = yamlCount(best["episode"]);
      record.best_worst_balanced = yamlCount(best["worst_balanced"]);
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

RunFolder::RunFolder(RunSettings settings, const TableStore& tables, std::function<std::time_t()> calendar)
  : settings_(std::move(settings)), tables_(tables), calendar_(std::move(calendar))
{
  record_.run_id = settings_.run_id;
  record_.name_space = settings_.name_space;
  record_.seed = settings_.seed;
}

bool RunFolder::madeAtStart() const
{
  return settings_.run_folder && (settings_.checkpoint_every > 0 || settings_.save_on_shutdown);
}

std::string RunFolder::file(const char* file) const
{
  return name_ + "/" + file;
}

RunOpening RunFolder::open(const RunIdentity& previous, int launcher, TrainingSession& session, LogLines& log)
{
  if (!settings_.run_folder)
    return RunOpening::Fresh;
  // A respawn has the run id and the launcher of the process that started the run; a node
  // started by hand on a reused master has at most the id left there.
  if (!settings_.run_id.empty() && previous.id == settings_.run_id && previous.launcher == launcher &&
      !previous.folder.empty())
  {
    name_ = previous.folder;
    return goOn(true, session, log);
  }
  return startNew(log);
}

void RunFolder::selectForResume(const std::string& folder)
{
  try
  {
    name_ = relativePathUnder(settings_.q_table_dir, withoutTrailingSlashes(folder));
  }
  catch (const FileError& e)
  {
    throw ConfigError("cannot resume the run '" + folder + "': " + e.what());
  }
}

RunOpening RunFolder::resume(TrainingSession& session, LogLines& log)
{
  return goOn(false, session, log);
}

RunOpening RunFolder::startNew(LogLines& log)
{
  const std::time_t now = calendar_();
  record_.started = localTimeText(now);
  name_ = runFolderName(now, settings_.name_space, settings_.seed);
  // Made now, so that a folder that cannot be written is said at the start, not at the first
  // checkpoint. A run told to write nothing along the way (no checkpoints, no save on shutdown)
  // writes nothing yet.
  deferred_ = !madeAtStart();
  try
  {
    if (madeAtStart())
    {
      makeUnderFreeName();
      writeFileUnder(settings_.q_table_dir, file(kRunRecordFile), formatRunRecord(record_));
    }
  }
  catch (const FileError& e)
  {
    const std::string save_service = settings_.names(Setting::SaveService);
    const std::string still = save_service.empty()
                                  ? "a solved table still goes to " + settings_.names(Setting::TablePath) + "'s path"
                                  : save_service + " can still save the table elsewhere";
    log.push_back({LogLine::Level::Error, formatText("cannot make this run's folder (%s): checkpoints will fail; %s",
                                                     e.what(), still.c_str())});
  }
  log.push_back({LogLine::Level::Info, formatText("run %s: checkpoints go to %s", name_.c_str(),
                                                  tables_.resolveForService(file(kRunTableFile)).c_str())});
  return RunOpening::Fresh;
}

void RunFolder::makeUnderFreeName()
{
  // A name taken (another run started in the same second) gets a suffix.
  const std::string base = name_;
  for (int n = 2; !makeDirectoryUnder(settings_.q_table_dir, name_); ++n)
    name_ = base + "_" + std::to_string(n);
}

void RunFolder::makeDeferred()
{
  deferred_ = false;
  makeUnderFreeName();
  new_name_ = true;
}

std::optional<std::string> RunFolder::takeNewName()
{
  if (!new_name_)
    return std::nullopt;
  new_name_ = false;
  return name_;
}

RunOpening RunFolder::goOn(bool respawn, TrainingSession& session, LogLines& log)
{
  resumed_ = true;
  const std::string table_path = file(kRunTableFile);
  RunRecord record;
  QTable table;
  try
  {
    record = parseRunRecord(readFileUnder(settings_.q_table_dir, file(kRunRecordFile), 1 << 20));
    table = tables_.load(table_path);
  }
  catch (const FileError& e)
  {
    if (!respawn)
      throw ConfigError("run " + name_ + " has no checkpoint to go on from: " + e.what());
    // Killed before its first checkpoint (or the checkpoint is unusable): the run starts over.
    record_.started = localTimeText(calendar_());
    log.push_back(
        {LogLine::Level::Warn, formatText("restarted; run %s has no checkpoint to go on from (%s): starting it over",
                                          name_.c_str(), e.what())});
    return RunOpening::StartedOver;
  }
  // A crash between the table's save and the record's leaves the record one checkpoint behind:
  // the table wins, and the solved window starts empty.
  const bool record_matches = record.episodes == table.episodes && record.steps == table.steps;
  const std::string mismatch =
      session.resume(std::move(table), record_matches ? record.recent_returns : std::vector<double>());
  if (!mismatch.empty())
    throw ConfigError(std::string(respawn ? "restarted, but the checkpoint " : "the checkpoint ") +
                      tables_.resolveForService(table_path) +
                      " does not fit this controller's configuration: " + mismatch);
  record_ = record;
  const EpisodeSummary& s = session.lastEpisode();
  if (record.finished.empty())
  {
    log.push_back(
        {LogLine::Level::Warn,
         formatText("%srun %s goes on from its checkpoint: episode %llu, %llu steps%s", respawn ? "restarted; " : "",
                    name_.c_str(), count(s.episode), count(s.total_steps),
                    record_matches ? "" : " (its record was one checkpoint behind: the solved window starts empty)")});
    return RunOpening::GoesOn;
  }
  // Ended (or killed) after its final save: nothing to train, and nothing said of going on. A
  // controller stays up rather than exit, which under respawn would only start it again.
  log.push_back({LogLine::Level::Info,
                 formatText("%srun %s has finished already (%s, episode %llu, %llu steps); nothing left to do",
                            respawn ? "restarted; " : "", name_.c_str(), record.finished.c_str(), count(s.episode),
                            count(s.total_steps))});
  return RunOpening::FinishedAlready;
}

bool RunFolder::checkpoint(const TrainingSession& session, const std::string& finished_as, const BestTable* best,
                           std::string& message)
{
  if (best && best->episode != best_saved_episode_)
  {
    try
    {
      tables_.save(best->table, file(kRunBestTableFile));
      best_saved_episode_ = best->episode;
    }
    catch (const std::exception& e)  // FileError, or anything else: never out of a service
    {
      message = std::string("nothing written: the best table: ") + e.what();
      return false;
    }
  }
  const ServiceAnswer saved = tables_.serveSave(session.table(), file(kRunTableFile));
  message = saved.message;
  if (!saved.success)
    return false;
  if (best && best_saved_episode_ > 0)
  {
    record_.best_episode = best->episode;
    record_.best_worst_balanced = best->result.worstBalanced();
    record_.best_robustness = best->result.summary();
  }
  record_.episodes = session.table().episodes;
  record_.steps = session.table().steps;
  record_.recent_returns = session.recentReturns();
  record_.finished = finished_as;
  try
  {
    writeFileUnder(settings_.q_table_dir, file(kRunRecordFile), formatRunRecord(record_));
  }
  catch (const std::exception& e)
  {
    message +=
        ", but not its run record (a restart would go on from the previous checkpoint): " + std::string(e.what());
    return false;
  }
  return true;
}

QTable RunFolder::loadBestTable() const
{
  return tables_.load(file(kRunBestTableFile));
}

std::string RunFolder::bestTablePath() const
{
  return tables_.resolveForService(file(kRunBestTableFile));
}

void RunFolder::bestTableKept(const BestTable& best)
{
  best_saved_episode_ = best.episode;
  record_.best_episode = best.episode;
  record_.best_worst_balanced = best.result.worstBalanced();
  record_.best_robustness = best.result.summary();
}

void RunFolder::bestTableLost()
{
  record_.best_episode = record_.best_worst_balanced = 0;
  record_.best_robustness.clear();
}

void RunFolder::setRobustness(const std::string& summary)
{
  record_.robustness = summary;
}

}  // namespace cartpole_qlearning
