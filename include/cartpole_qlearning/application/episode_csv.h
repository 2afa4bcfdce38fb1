// The learning curve as a file: one CSV row per episode, written as each episode ends, for
// plot_learning_curve, a spreadsheet or pandas. The columns are those of EpisodeStats (the
// learner's episode_stats), plus the wall-clock time the episode ended:
//   episode,robot,steps,episode_return,mean_return_100,epsilon,alpha,terminated,truncated,solved,total_steps,wall_time,gamma
// Numbers are written in their shortest exact form (a reader gets the very doubles back),
// booleans as true/false, wall_time as Unix seconds.
#pragma once

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <cstdint>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
// The file name of a training run's curve, beside its checkpoint in the run's folder.
constexpr const char* kRunEpisodesFile = "episodes.csv";

// The header line, without its newline.
extern const char* const kEpisodeCsvHeader;

// One row, without its newline. robot: the robot's namespace ("" for the learner's own).
std::string episodeCsvRow(const EpisodeSummary& summary, const std::string& robot, double wall_time);

class EpisodeCsvWriter
{
public:
  // A new curve: the curve the file held goes, and the header is written. A file that holds
  // something else is refused (FileError) and left as it was.
  explicit EpisodeCsvWriter(AppendingFile file);
  // A run that goes on from its checkpoint after `episodes` episodes (a respawned controller):
  // the header and the rows of episodes up to that number stay, later rows go (the run plays
  // those episodes again, so the file never holds an episode twice), as does a last line cut
  // short. An empty file gets the header. A file that does not start with this header is
  // refused (FileError) and left as it was: it is not a curve of this package.
  EpisodeCsvWriter(AppendingFile file, std::uint64_t episodes);

  // Adds the episode's row: one write, so a reader following the file sees it whole at once.
  // Throws FileError.
  void write(const EpisodeSummary& summary, const std::string& robot, double wall_time);
  // Empties the curve down to its header: a loaded table brings episode numbers of its own, and
  // a curve holds one numbering (a resume keeps rows by their numbers). Throws FileError.
  void startOver();

  const std::string& path() const
  {
    return file_.path();
  }

private:
  AppendingFile file_;
};

}  // namespace cartpole_qlearning
