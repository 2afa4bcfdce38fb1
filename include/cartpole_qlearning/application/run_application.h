// The application around the learner: one training or evaluation run, as the controller node
// and train_headless carry it out. It puts the parts together and decides what happens at each
// moment of a run: at the start (the table of ~load_on_start, a new run or the respawn of one), at
// each episode's end (the curve's row, the suite, the end of training and its saves, checkpoints,
// progress, the evaluation's verdict), on the services and on shutdown. The parts:
//   TableStore       the table folder, the default table and the path rule; the services' answers
//   RunFolder        the run's folder: its name, record, checkpoints, respawn and resume
//   LearningCurve    one CSV row per episode
//   BestTableKeeper  the robustness suite during training and the best table it has seen
//   RunMeters        rates, progress lines, the evaluation's verdict
// It returns what to say as values (as ControllerProtocol returns a Reaction), with its clocks
// injected, so that the node and train_headless carry out the same decisions and every decision
// is a unit test. The controller node logs what it says on its named logger; train_headless
// prints it.
#pragma once

#include "cartpole_qlearning/application/best_table_keeper.h"
#include "cartpole_qlearning/application/learning_curve.h"
#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/application/run_folder.h"
#include "cartpole_qlearning/application/run_meters.h"
#include "cartpole_qlearning/application/table_store.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <chrono>
#include <ctime>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
// The clocks a run reads, injected so that tests drive them.
struct RunClocks
{
  // Rates and durations (steps per second, the time a run took).
  std::function<std::chrono::steady_clock::time_point()> steady = [] { return std::chrono::steady_clock::now(); };
  // The CSV's wall_time column (Unix seconds).
  std::function<double()> unix_seconds = [] {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  };
  // Run folder names and the record's start time (local time).
  std::function<std::time_t()> calendar = [] { return std::time(nullptr); };
};

// What the caller does after an episode's end.
struct EpisodeEnd
{
  LogLines log;
  // For episode_stats: the learner's steps per second since the previous episode's end (any
  // robot), and this robot's since its own previous end.
  double steps_per_second = 0.0;
  double robot_steps_per_second = 0.0;
  // Training reached its limits and its table is saved, or the evaluation has its verdict: end
  // the launch when asked to. (When the final save failed this stays false while finished()
  // turns true: no more states are served, and the node stays up for ~save_q_table.)
  bool finished = false;
  // The run's folder was made or renamed now: the node stores it (~run/folder) for a respawn.
  std::optional<std::string> run_folder;
  // Training ended here: the robustness suite's summary of the table it saved (episode_stats'
  // robustness); "" otherwise, or when there is no suite (training/suite none).
  std::string robustness;
  // Training ended here: whether it got where it trained to (solved; under until suite_passes, the
  // suite passed; when it goes on after solved, max_episodes: always, ended here).
  bool goal_reached = false;
  // Training ended here: the wall seconds the saved table's final verdict (the suite) took, apart
  // from the training's.
  double verdict_seconds = 0.0;
};

class RunApplication
{
public:
  // session: the learner; it outlives this. config: the training configuration in use (limits,
  // the task's solved window and step limit, the features for the trace).
  RunApplication(RunSettings settings, const TrainingConfig& config, TrainingSession& session, RunClocks clocks = {});
  ~RunApplication();

  RunApplication(const RunApplication&) = delete;
  RunApplication& operator=(const RunApplication&) = delete;

  // Starts the run: the table of load_on_start, the curve, the suite (training), and (training)
  // this run's folder, or, when `previous` names this very run (same id and launcher: a respawn), goes on from its
  // checkpoint. launcher: this process's roslaunch (else parent) pid, 0 when not applicable
  // (train_headless). Throws ConfigError naming the parameter for what must stop the node: a
  // ~load_on_start table that cannot be used, a ~stats_csv that cannot be written (a
  // RunSettingError), a checkpoint that does not fit the configuration, a training/suite that
  // cannot be read when training evaluates it (suite_every > 0; else a warning says that the run
  // ends without a verdict).
  LogLines start(const RunIdentity& previous = {}, int launcher = 0);
  // What start() would refuse, found without starting: the suite training evaluates with and the
  // table to load (its file, its fit, its config), throwing as start() throws. Writes nothing and
  // judges nothing (a launch checks its nodes' parameters with it before they start).
  void checkStart();
  // train_headless --resume FOLDER: goes on from that run folder's checkpoint (relative: under
  // the table folder), instead of start(): ~load_on_start plays no part, the curve keeps the rows
  // the checkpoint covers. Throws ConfigError when it holds no usable checkpoint, when the folder
  // escapes the table folder, or when evaluating.
  LogLines resume(const std::string& folder);

  // An episode has just ended on robot `robot` (its namespace, "" for the learner's own): the
  // session's lastEpisode(). training_finished: the protocol (or the headless loop) says
  // training reached its limits with this episode. Training also ends here when the suite,
  // evaluated at this episode, passes under training/until suite_passes (EpisodeEnd::finished,
  // finished()): the caller then serves no more states.
  EpisodeEnd endEpisode(const std::string& robot, bool training_finished);

  // The services: paths relative to the table folder (empty: the default table); a path that
  // escapes the folder is refused. Never throw.
  ServiceAnswer save(const std::string& path);
  ServiceAnswer load(const std::string& path);
  // The same in steps, so that a controller writes and reads files (seconds for a large table)
  // while it goes on serving states. Save: tableOfThisShape() at any time (a table of zeros of the
  // run's shape: allocating the memory is the slow part of a copy, 0.7 s measured for the largest
  // table on a loaded machine), then copyTableInto() it while nothing changes the table in use (the
  // values copied into that memory), then saveCopy() at any time. Load: readTable() at any time (a
  // file larger than this run's table could be is refused unread), then useTable() while nothing
  // else uses the table. tableOfThisShape(), saveCopy() and readTable() touch only what is fixed
  // for the run: safe on another thread beside every other call.
  QTable tableOfThisShape() const;
  void copyTableInto(QTable& copy) const;
  ServiceAnswer saveCopy(const QTable& copy, const std::string& path) const;
  TableRead readTable(const std::string& path) const;
  ServiceAnswer useTable(TableRead read);

  // The process is going away: the save on shutdown into the run's folder (training, when
  // asked and when the final save has not happened).
  LogLines shutdown();

  // What a respawn needs to find this run (empty id: nothing to store).
  RunIdentity identity() const;
  bool respawned() const;  // start() went on with a run a dead controller started
  bool finished() const;   // nothing left to do (a respawn of a finished run, training over, verdict given)
  EvaluationVerdict verdict() const;
  // A path as the services take it, made absolute ("": the default table; throws FileError when
  // it escapes the table folder).
  std::string resolve(const std::string& path) const;
  const std::string& tableDirectory() const;
  const std::string& runFolder() const;  // "" when evaluating

private:
  struct Parts;
  std::unique_ptr<Parts> parts_;
};

}  // namespace cartpole_qlearning
