// A training run's own folder under the table folder: its name, its checkpoints (the table, and
// the best table the robustness suite has seen) and its record (what a restarted controller needs
// to go on where the run was: the solved window's recent returns, and whether the run has
// finished), the respawn of the controller that started it and train_headless --resume. Runs
// never write each other's files; the table users evaluate by default is a separate file,
// replaced only by a solved run or an explicit save (RunApplication decides which).
#pragma once

#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <cstdint>
#include <ctime>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The files in a run's folder.
constexpr const char* kRunTableFile = "q_table.yaml";
constexpr const char* kRunRecordFile = "run.yaml";
// The best table the robustness suite has seen in the run (training/suite_every > 0), which a
// resumed run goes on comparing against.
constexpr const char* kRunBestTableFile = "best_q_table.yaml";
// The run's learning curve (learning_curve.h), when ~stats_csv names no other file.
constexpr const char* kRunEpisodesFile = "episodes.csv";
// Where run folders go, under the table directory.
constexpr const char* kRunsFolder = "runs";

struct RunRecord
{
  std::string run_id;      // the launch that started the run (roslaunch's $(anon ...)): a respawn finds it by this
  std::string name_space;  // the learner's ROS namespace
  std::uint64_t seed = 0;
  std::string started;  // local time, "YYYY-MM-DD HH:MM:SS"
  // Of the checkpoint table beside the record (a record whose counts differ from its table's
  // was written by a save that a crash cut short between the two files).
  std::uint64_t episodes = 0;
  std::uint64_t steps = 0;
  std::vector<double> recent_returns;  // the solved window at the checkpoint, oldest first
  std::string finished;                // "" while the run goes on; "solved", "suite_passed" or "max_episodes"
  // What the final table is worth: the robustness suite's one-line summary (robustness_suite.h),
  // written when training ends ("": not evaluated).
  std::string robustness;
  // The best table the suite has seen so far (kRunBestTableFile beside the record, saved before
  // it): the episode it was evaluated at (0: none yet), its worst case's balanced episodes and the
  // suite's summary of it. What the user reads; a resumed run evaluates that file again.
  std::uint64_t best_episode = 0;
  std::uint64_t best_worst_balanced = 0;
  std::string best_robustness;
};

// The record as YAML, and back. parseRunRecord throws FileError saying what is wrong.
std::string formatRunRecord(const RunRecord& record);
RunRecord parseRunRecord(const std::string& text);

// "runs/2026-11-22_14-03-05_cartpole_seed0": the time a run started (local), its namespace
// (slashes as underscores; "root" for "/") and its seed.
std::string runFolderName(std::time_t started, const std::string& name_space, std::uint64_t seed);
// "2026-11-22 14:03:05"
std::string localTimeText(std::time_t when);

// What identifies a run to a respawn of the controller that started it (the node keeps it on
// the parameter server as ~run/id, ~run/launcher, ~run/folder).
struct RunIdentity
{
  std::string id;      // ~run_id ("": runs are not resumed)
  int launcher = 0;    // the roslaunch (else the parent) process that started the run
  std::string folder;  // relative to the table folder
};

// The best table the robustness suite has seen in a run: what a checkpoint saves beside the
// run's table (kRunBestTableFile) and names in the record.
struct BestTable
{
  QTable table;
  SuiteResult result;
  std::uint64_t episode = 0;  // the episode it was evaluated at
};

// How a run found its folder at the start.
enum class RunOpening
{
  Fresh,           // a new run (or no run folder at all)
  StartedOver,     // a respawn whose run had no usable checkpoint: the same folder, from scratch
  GoesOn,          // from the run's checkpoint
  FinishedAlready  // the run had ended after its final save: nothing left to do
};

class RunFolder
{
public:
  // settings: the run's id, namespace and seed (its record and name), whether it has a folder at
  // all (run_folder) and whether it writes along the way (checkpoint_every, save_on_shutdown).
  // calendar: the local time a run starts (its name and record).
  RunFolder(RunSettings settings, const TableStore& tables, std::function<std::time_t()> calendar);

  // At the start of training: a respawn of the controller that started the run `previous` names
  // (same id and launcher) goes on from its checkpoint, anything else starts a new run. A new run
  // that writes along the way makes its folder and record now (a name taken gets a suffix);
  // else the folder waits for the first thing written (makeDeferred). launcher: this process's
  // roslaunch (else parent) pid. Throws ConfigError when a checkpoint does not fit the session.
  RunOpening open(const RunIdentity& previous, int launcher, TrainingSession& session, LogLines& log);
  // train_headless --resume: the run in `folder` (relative: under the table folder; throws
  // ConfigError when it escapes it), then going on from its checkpoint (throws ConfigError when
  // there is none usable, or it does not fit the session).
  void selectForResume(const std::string& folder);
  RunOpening resume(TrainingSession& session, LogLines& log);

  // A new run whose folder waits for the first thing written (no checkpoints, no save on shutdown).
  bool isDeferred() const
  {
    return deferred_;
  }
  // Makes that folder now, under a name no other run has taken. Throws FileError.
  void makeDeferred();
  // The folder's name when it was made by makeDeferred since the last call (the node stores it
  // for a respawn), else nothing.
  std::optional<std::string> takeNewName();

  // Saves the session's table into the folder, and the record after it (the best table first,
  // when there is a best not saved yet: a record never names a best that is not on disk).
  // finished_as: the record's `finished` ("" while the run goes on). False when something could
  // not be written; message says what was written or why not.
  bool checkpoint(const TrainingSession& session, const std::string& finished_as, const BestTable* best,
                  std::string& message);

  // The best table the record names (loaded from the folder; throws FileError), and what a
  // resumed run then knows of it.
  QTable loadBestTable() const;
  std::string bestTablePath() const;  // absolute, for messages
  void bestTableKept(const BestTable& best);
  void bestTableLost();
  // What the final table is worth (the suite's one-line summary), written at the next checkpoint.
  void setRobustness(const std::string& summary);

  const RunRecord& record() const
  {
    return record_;
  }
  // Relative to the table folder ("" when evaluating, or without run folder).
  const std::string& name() const
  {
    return name_;
  }
  // The folder's file `file` (kRunTableFile, ...), relative to the table folder.
  std::string file(const char* file) const;
  // A run (respawned, or resumed by train_headless) that went on with a folder already there.
  bool resumed() const
  {
    return resumed_;
  }

private:
  RunOpening startNew(LogLines& log);
  RunOpening goOn(bool respawn, TrainingSession& session, LogLines& log);
  // Writes along the way: the folder is made at the start.
  bool madeAtStart() const;
  // Makes the folder under name_, or name_ with a suffix when taken.
  void makeUnderFreeName();

  RunSettings settings_;
  const TableStore& tables_;  // outlives this
  std::function<std::time_t()> calendar_;
  RunRecord record_;
  std::string name_;
  bool resumed_ = false;
  bool deferred_ = false;
  bool new_name_ = false;
  std::uint64_t best_saved_episode_ = 0;  // the best table in the folder (0: none)
};

}  // namespace cartpole_qlearning
