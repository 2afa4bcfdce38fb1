#include "cartpole_qlearning/application/learning_curve.h"
#include "cartpole_qlearning/io/number_text.h"

#include <charconv>
#include <cstdio>
#include <cstdlib>

namespace cartpole_qlearning
{
const char* const kLearningCurveHeader =
    "episode,robot,steps,episode_return,mean_return_100,epsilon,alpha,terminated,truncated,solved,total_steps,"
    "wall_time,gamma";

namespace
{
// Shortest text that reads back as the same double, whatever the locale.
std::string exact(double value)
{
  return shortestText(value);
}

const char* yesNo(bool value)
{
  return value ? "true" : "false";
}

// A robot's namespace as a CSV field: quoted only when it has to be (ROS names never need it).
std::string field(const std::string& text)
{
  if (text.find_first_of(",\"\n\r") == std::string::npos)
    return text;
  std::string quoted = "\"";
  for (char c : text)
    quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// The episode number a row starts with, or nothing when the line is not a whole row.
std::optional<std::uint64_t> rowEpisode(const std::string& line)
{
  std::uint64_t episode = 0;
  const auto result = std::from_chars(line.data(), line.data() + line.size(), episode);
  if (result.ec != std::errc() || result.ptr == line.data() + line.size() || *result.ptr != ',')
    return std::nullopt;
  return episode;
}
}  // namespace

std::string learningCurveRow(const EpisodeSummary& s, const std::string& robot, double wall_time)
{
  char time[32];
  std::snprintf(time, sizeof time, "%.3f", wall_time);
  return std::to_string(s.episode) + "," + field(robot) + "," + std::to_string(s.steps) + "," +
         exact(s.episode_return) + "," + exact(s.mean_return_window) + "," + exact(s.epsilon) + "," + exact(s.alpha) +
         "," + yesNo(s.terminated) + "," + yesNo(s.truncated) + "," + yesNo(s.solved) + "," +
         std::to_string(s.total_steps) + "," + time + "," + exact(s.gamma);
}

LearningCurveFile::LearningCurveFile(AppendingFile file) : file_(std::move(file))
{
  // Only a curve is replaced: a path that names a table or notes by mistake must not lose them.
  // (Any version of the curve counts: its first columns have always been these.)
  const std::string text = file_.read();
  if (!text.empty() && text.rfind("episode,robot,steps,", 0) != 0)
    throw FileError(file_.path() + " is not an episode CSV of cartpole_qlearning (its first line is not '" +
                    kLearningCurveHeader + "'): refused, left as it was; name a new file, or an old curve to replace");
  startOver();
}

LearningCurveFile::LearningCurveFile(AppendingFile file, std::uint64_t episodes) : file_(std::move(file))
{
  const std::string text = file_.read();
  const std::string header = std::string(kLearningCurveHeader) + "\n";
  if (text.empty())
  {
    file_.append(header);
    return;
  }
  if (text.compare(0, header.size(), header) != 0)
    throw FileError(file_.path() + " is not an episode CSV of cartpole_qlearning (its first line is not '" +
                    kLearningCurveHeader + "'): refused, left as it was");
  keepUpTo(episodes);
}

std::uint64_t LearningCurveFile::keepUpTo(std::uint64_t episodes)
{
  const std::string text = file_.read();
  // Rows are kept up to the first one past `episodes`, or the first cut short.
  std::size_t keep = text.find('\n') == std::string::npos ? text.size() : text.find('\n') + 1;
  std::uint64_t last = 0;
  while (keep < text.size())
  {
    const std::size_t end = text.find('\n', keep);
    if (end == std::string::npos)
      break;
    const std::optional<std::uint64_t> episode = rowEpisode(text.substr(keep, end - keep));
    if (!episode || *episode > episodes)
      break;
    last = *episode;
    keep = end + 1;
  }
  if (keep < text.size())
    file_.truncate(keep);
  return last;
}

void LearningCurveFile::startOver()
{
  file_.truncate(0);
  file_.append(std::string(kLearningCurveHeader) + "\n");
}

void LearningCurveFile::write(const EpisodeSummary& summary, const std::string& robot, double wall_time)
{
  file_.append(learningCurveRow(summary, robot, wall_time) + "\n");
}

RunSettingError::RunSettingError(Setting setting_, const SettingNames& names, const std::string& value_,
                                 const std::string& why_)
  : ConfigError(names(setting_) + " = " + value_ + " is not allowed (" + why_ + ")"),
    setting(setting_),
    value(value_),
    why(why_)
{
}

LearningCurve::LearningCurve(const RunSettings& settings, RunFolder& folder, std::function<double()> unix_seconds)
  : stats_csv_(settings.stats_csv),
    names_(settings.names),
    table_dir_(settings.q_table_dir),
    learning_(settings.learning()),
    run_folder_(settings.run_folder),
    folder_(folder),
    unix_seconds_(std::move(unix_seconds))
{
}

void LearningCurve::openUsersFile()
{
  if (stats_csv_ == "none" || stats_csv_.empty())
    return;
  try
  {
    opened_ = std::make_unique<AppendingFile>(
        stats_csv_.front() == '/' ? AppendingFile::open(stats_csv_) : AppendingFile::openUnder(table_dir_, stats_csv_));
  }
  catch (const FileError& e)
  {
    throw RunSettingError(Setting::StatsCsv, names_, "'" + stats_csv_ + "'", e.what());
  }
}

void LearningCurve::start(std::uint64_t episodes, LogLines& log)
{
  if (stats_csv_ == "none" || (stats_csv_.empty() && (!learning_ || !run_folder_)))
    return;
  // A run told to write nothing along the way (no checkpoints, no save on shutdown) makes its
  // folder only when there is something to write: at the first episode's end.
  if (!opened_ && folder_.isDeferred())
  {
    waiting_for_folder_ = true;
    return;
  }
  open(episodes, log);
}

void LearningCurve::open(std::uint64_t episodes, LogLines& log)
{
  if (!opened_)
  {
    // The run folder's file: beside its checkpoints.
    try
    {
      if (waiting_for_folder_)
        folder_.makeDeferred();
      waiting_for_folder_ = false;
      opened_ = std::make_unique<AppendingFile>(AppendingFile::openUnder(table_dir_, folder_.file(kRunEpisodesFile)));
    }
    catch (const FileError& e)
    {
      waiting_for_folder_ = false;
      log.push_back({LogLine::Level::Error, "no learning curve for this run (" + names_(Setting::StatsCsv) +
                                                " none silences this): " + e.what()});
      return;
    }
  }
  try
  {
    // A resumed run goes on with its curve from the checkpoint it resumed (a run that starts
    // over keeps the header alone); anything else starts the curve afresh.
    file_ = folder_.resumed() ? std::make_unique<LearningCurveFile>(std::move(*opened_), episodes)
                              : std::make_unique<LearningCurveFile>(std::move(*opened_));
  }
  catch (const FileError& e)
  {
    opened_.reset();
    if (!stats_csv_.empty())
      throw RunSettingError(Setting::StatsCsv, names_, "'" + stats_csv_ + "'", e.what());
    log.push_back({LogLine::Level::Error, "no learning curve for this run (" + names_(Setting::StatsCsv) +
                                              " none silences this): " + e.what()});
    return;
  }
  opened_.reset();
  log.push_back({LogLine::Level::Info, "one row per episode goes to " + file_->path() + " (" +
                                           names_(Setting::CurveViewer) + " " + file_->path() + ")"});
}

void LearningCurve::write(const std::string& robot, const EpisodeSummary& summary, LogLines& log)
{
  if (waiting_for_folder_)
    open(0, log);
  if (!file_)
    return;
  try
  {
    file_->write(summary, robot, unix_seconds_());
  }
  catch (const FileError& e)
  {
    log.push_back({LogLine::Level::Error, std::string("the learning curve stops here: ") + e.what()});
    file_.reset();
  }
}

void LearningCurve::startOver(std::uint64_t episodes, LogLines& log)
{
  if (!learning_ || !file_)
    return;
  try
  {
    // A table of this run's own (saved now or at an earlier episode, then loaded) goes on where
    // it was: the rows up to its episode stay. One that comes from further than this curve went
    // is another run's, and its numbering starts a curve of its own.
    if (episodes > 0 && file_->keepUpTo(episodes) == episodes)
    {
      log.push_back({LogLine::Level::Info,
                     formatText("the learning curve %s goes on from the loaded table's episode %llu (the rows after it "
                                "dropped)",
                                file_->path().c_str(), static_cast<unsigned long long>(episodes))});
      return;
    }
    file_->startOver();
    log.push_back(
        {LogLine::Level::Info, formatText("the learning curve %s starts over from the loaded table's episode %llu",
                                          file_->path().c_str(), static_cast<unsigned long long>(episodes))});
  }
  catch (const FileError& e)
  {
    log.push_back({LogLine::Level::Warn, std::string(e.what()) + "; the learning curve stops here"});
    file_.reset();
  }
}

}  // namespace cartpole_qlearning
