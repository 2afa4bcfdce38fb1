#include "cartpole_qlearning/application/episode_csv.h"

#include <charconv>
#include <cstdio>
#include <cstdlib>

namespace cartpole_qlearning
{
const char* const kEpisodeCsvHeader =
    "episode,robot,steps,episode_return,mean_return_100,epsilon,alpha,terminated,truncated,solved,total_steps,"
    "wall_time,gamma";

namespace
{
// Shortest text that reads back as the same double, whatever the locale.
std::string exact(double value)
{
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
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

std::string episodeCsvRow(const EpisodeSummary& s, const std::string& robot, double wall_time)
{
  char time[32];
  std::snprintf(time, sizeof time, "%.3f", wall_time);
  return std::to_string(s.episode) + "," + field(robot) + "," + std::to_string(s.steps) + "," +
         exact(s.episode_return) + "," + exact(s.mean_return_window) + "," + exact(s.epsilon) + "," + exact(s.alpha) +
         "," + yesNo(s.terminated) + "," + yesNo(s.truncated) + "," + yesNo(s.solved) + "," +
         std::to_string(s.total_steps) + "," + time + "," + exact(s.gamma);
}

EpisodeCsvWriter::EpisodeCsvWriter(AppendingFile file) : file_(std::move(file))
{
  // Only a curve is replaced: a path that names a table or notes by mistake must not lose them.
  // (Any version of the curve counts: its first columns have always been these.)
  const std::string text = file_.read();
  if (!text.empty() && text.rfind("episode,robot,steps,", 0) != 0)
    throw FileError(file_.path() + " is not an episode CSV of cartpole_qlearning (its first line is not '" +
                    kEpisodeCsvHeader + "'): refused, left as it was; name a new file, or an old curve to replace");
  startOver();
}

EpisodeCsvWriter::EpisodeCsvWriter(AppendingFile file, std::uint64_t episodes) : file_(std::move(file))
{
  const std::string text = file_.read();
  const std::string header = std::string(kEpisodeCsvHeader) + "\n";
  if (text.empty())
  {
    file_.append(header);
    return;
  }
  if (text.compare(0, header.size(), header) != 0)
    throw FileError(file_.path() + " is not an episode CSV of cartpole_qlearning (its first line is not '" +
                    kEpisodeCsvHeader + "'): refused, left as it was");
  // Rows are kept up to the first one the checkpoint did not cover, or the first cut short.
  std::size_t keep = header.size();
  while (keep < text.size())
  {
    const std::size_t end = text.find('\n', keep);
    if (end == std::string::npos)
      break;
    const std::optional<std::uint64_t> episode = rowEpisode(text.substr(keep, end - keep));
    if (!episode || *episode > episodes)
      break;
    keep = end + 1;
  }
  if (keep < text.size())
    file_.truncate(keep);
}

void EpisodeCsvWriter::startOver()
{
  file_.truncate(0);
  file_.append(std::string(kEpisodeCsvHeader) + "\n");
}

void EpisodeCsvWriter::write(const EpisodeSummary& summary, const std::string& robot, double wall_time)
{
  file_.append(episodeCsvRow(summary, robot, wall_time) + "\n");
}

}  // namespace cartpole_qlearning
