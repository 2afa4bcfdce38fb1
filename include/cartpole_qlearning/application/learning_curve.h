// The learning curve as a file: one CSV row per episode, written as each episode ends, for
// plot_learning_curve, a spreadsheet or pandas. The columns are those of EpisodeStats (the
// learner's episode_stats), plus the wall-clock time the episode ended:
//   episode,robot,steps,episode_return,mean_return_100,epsilon,alpha,terminated,truncated,solved,total_steps,wall_time,gamma
// Numbers are written in their shortest exact form (a reader gets the very doubles back),
// booleans as true/false, wall_time as Unix seconds.
//
// LearningCurveFile writes such a file; LearningCurve is a run's curve: where it goes (~stats_csv:
// the run folder's episodes.csv, a file of the user's, or none), when it is opened, and what
// happens to it on a respawn (it goes on) or a loaded table (it starts over).
#pragma once

#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/application/run_folder.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/io/appending_file.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
// The header line, without its newline.
extern const char* const kLearningCurveHeader;

// One row, without its newline. robot: the robot's namespace ("" for the learner's).
std::string learningCurveRow(const EpisodeSummary& summary, const std::string& robot, double wall_time);

class LearningCurveFile
{
public:
  // A new curve: the curve the file held goes, and the header is written. A file that holds
  // something else is refused (FileError) and left as it was.
  explicit LearningCurveFile(AppendingFile file);
  // A run that goes on from its checkpoint after `episodes` episodes (a respawned controller):
  // the header and the rows of episodes up to that number stay, later rows go (the run plays
  // those episodes again, so the file never holds an episode twice), as does a last line cut
  // short. An empty file gets the header. A file that does not start with this header is
  // refused (FileError) and left as it was: it is not a curve of this package.
  LearningCurveFile(AppendingFile file, std::uint64_t episodes);

  // Adds the episode's row: one write, so a reader following the file sees it whole at once.
  // Throws FileError.
  void write(const EpisodeSummary& summary, const std::string& robot, double wall_time);
  // Empties the curve down to its header: a loaded table brings episode numbers of its own, and
  // a curve holds one numbering (a resume keeps rows by their numbers). Throws FileError.
  void startOver();
  // Drops the rows after episode `episodes` (and a last line cut short); returns the episode of
  // the last row kept (0: none). Throws FileError.
  std::uint64_t keepUpTo(std::uint64_t episodes);

  const std::string& path() const
  {
    return file_.path();
  }

private:
  AppendingFile file_;
};

// A setting the run cannot work with (a learning curve's file that cannot be written): a
// ConfigError that keeps which setting, its value and why, so that each front end names the
// setting as it names its others. what(): "NAME = VALUE is not allowed (WHY)", NAME as `names`
// says it.
class RunSettingError : public ConfigError
{
public:
  RunSettingError(Setting setting, const SettingNames& names, const std::string& value, const std::string& why);
  Setting setting;
  std::string value;
  std::string why;
};

class LearningCurve
{
public:
  // settings: stats_csv ("" the run folder's file, when training with a run folder; "none"; else
  // a path: relative under q_table_dir, absolute the user's own) and learning. folder: the run's
  // (outlives this). unix_seconds: the wall_time column's clock.
  LearningCurve(const RunSettings& settings, RunFolder& folder, std::function<double()> unix_seconds);

  // Before the run folder opens: a file of the user's is opened now, so that one that cannot be
  // written stops the start. Throws RunSettingError.
  void openUsersFile();
  // After the run folder opened: the curve starts. A resumed run keeps the rows its checkpoint
  // covers (`episodes`); anything else starts afresh. The run folder's file waits for its folder
  // when that is made at the first episode's end. Throws RunSettingError when the user's file is
  // not a curve (left as it was); the run folder's file that cannot be opened is said.
  void start(std::uint64_t episodes, LogLines& log);
  // The episode's row; a file that cannot be written is said, and the curve stops there.
  void write(const std::string& robot, const EpisodeSummary& summary, LogLines& log);
  // A table was loaded: its episode numbers are the curve's from now (`episodes` of them done).
  void startOver(std::uint64_t episodes, LogLines& log);

private:
  void open(std::uint64_t episodes, LogLines& log);

  std::string stats_csv_;
  SettingNames names_;  // how the front end names the settings (the curve file's, whose "none" asks for none)
  std::string table_dir_;
  bool learning_;
  bool run_folder_;
  RunFolder& folder_;
  std::function<double()> unix_seconds_;
  std::unique_ptr<AppendingFile> opened_;  // opened, its curve not started yet
  std::unique_ptr<LearningCurveFile> file_;
  bool waiting_for_folder_ = false;  // the run folder's file, opened at the first episode's end
};

}  // namespace cartpole_qlearning
