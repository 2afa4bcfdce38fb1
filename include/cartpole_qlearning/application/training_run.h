// A training run's own folder: its checkpoints (the table) and its record (what a restarted
// controller needs to go on where the run was: the solved window's recent returns, and whether
// the run has finished). Runs never write each other's files; the table users evaluate by
// default is a separate file, replaced only by a solved run or an explicit save.
#pragma once

#include "cartpole_qlearning/io/file_access.h"

#include <cstdint>
#include <ctime>
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
  // written when training ends ("": not judged).
  std::string robustness;
  // The best table the suite has judged so far (kRunBestTableFile beside the record, saved before
  // it): the episode it was judged at (0: none yet), its worst case's balanced episodes and the
  // suite's summary of it. What the user reads; a resumed run judges that file again.
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

}  // namespace cartpole_qlearning
