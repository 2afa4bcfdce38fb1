#include "cartpole_qlearning/application/run_application.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/learning/trace.h"

#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <map>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
unsigned long long count(std::uint64_t value)
{
  return static_cast<unsigned long long>(value);
}

void say(LogLines& log, LogLine::Level level, std::string text)
{
  log.push_back({level, std::move(text)});
}

double seconds(std::chrono::steady_clock::duration duration)
{
  return std::chrono::duration<double>(duration).count();
}

// A table that passes beats one that does not; then the more balanced in its worst case.
bool better(const SuiteResult& a, const SuiteResult& b)
{
  return std::make_pair(a.passed(), a.worstBalanced()) > std::make_pair(b.passed(), b.worstBalanced());
}
}  // namespace

RunSettingError::RunSettingError(const std::string& name_, const std::string& value_, const std::string& why_)
  : ConfigError("~" + name_ + " = " + value_ + " is not allowed (" + why_ + ")"), name(name_), value(value_), why(why_)
{
}

struct RunApplication::State
{
  State(RunSettings settings_, const TrainingConfig& config_, TrainingSession& session_, RunClocks clocks_)
    : settings(std::move(settings_)), config(config_), session(session_), clocks(std::move(clocks_))
  {
    if (settings.trace && settings.learning)
      state_names = stateNames(config.agent);
  }

  // Writing the user's choices at each moment of a run.
  bool writesAlong() const
  {
    return settings.run_folder && (settings.checkpoint_every > 0 || settings.save_on_shutdown);
  }
  // A table path of the settings that is the user's own (see RunSettings::own_absolute_paths).
  bool own(const std::string& path) const
  {
    return settings.own_absolute_paths && !path.empty() && path.front() == '/';
  }
  std::string resolve(const std::string& path) const
  {
    if (path.empty() && own(settings.q_table_path))
      return settings.q_table_path;
    return resolvePathUnder(settings.q_table_dir, path.empty() ? settings.q_table_path : path);
  }

  std::string install(QTable table);
  bool save(const std::string& path, std::string& message);
  bool checkpoint(const std::string& finished_as, std::string& message);
  void loadOnStart(LogLines& log);
  void openStatsFile();
  void openRun(const RunIdentity& previous, LogLines& log);
  // respawn: a respawned controller (else train_headless --resume, which must find a checkpoint).
  void resumeRun(bool respawn, LogLines& log);
  void startStatsCsv(LogLines& log);
  void writeStatsRow(const std::string& robot, const EpisodeSummary& summary, LogLines& log);
  void startClocks();
  void loadSuite(LogLines& log);
  // Judges the session's table on the suite at this episode, keeping it when it is the best so far.
  SuiteResult judge(std::uint64_t episode);
  // A resumed run goes on comparing against the best table its folder holds (judged again).
  void restoreBest(LogLines& log);

  RunSettings settings;
  TrainingConfig config;
  TrainingSession& session;
  RunClocks clocks;
  std::vector<std::string> state_names;  // as the trace names the rows

  int launcher = 0;
  RunRecord run;
  std::string run_folder;  // relative to the table folder ("" when evaluating)
  bool respawned = false;  // going on with the run of a controller that died
  bool finished = false;
  bool final_saved = false;  // training ended and its table is saved (else a shutdown saves it)
  bool shut_down = false;

  std::unique_ptr<AppendingFile> stats_file;  // opened, its curve not started yet
  std::unique_ptr<EpisodeCsvWriter> csv;
  bool csv_pending = false;  // the run's own file, opened at the first episode's end
  bool folder_made_late = false;

  std::uint64_t balanced = 0;

  std::unique_ptr<RobustnessSuite> suite;  // none: no verdict (training/suite none, or not found)
  std::string suite_path;
  std::unique_ptr<QTable> best;  // the best table judged so far (suite_every > 0) and its verdict
  SuiteResult best_result;
  std::uint64_t best_episode = 0;
  std::uint64_t best_saved_episode = 0;  // the best table in the run's folder (0: none)

  std::chrono::steady_clock::time_point started;
  std::chrono::steady_clock::time_point last_episode_end;
  std::chrono::steady_clock::time_point last_progress;
  std::map<std::string, std::chrono::steady_clock::time_point> robot_last_end;
  std::uint64_t steps_at_last_episode = 0;
  std::uint64_t steps_at_last_progress = 0;
};

std::string RunApplication::State::install(QTable table)
{
  // Training goes on with the table's own counts: episode numbers, steps, the schedules and
  // max_episodes all count from them, so the progress lines and the saves agree. (The solved
  // window starts empty.) Evaluation counts its own episodes from 1.
  const std::string mismatch =
      settings.learning ? session.resume(std::move(table), {}) : session.replaceTable(std::move(table));
  // Steps per second count from here.
  steps_at_last_episode = steps_at_last_progress = session.lastEpisode().total_steps;
  return mismatch;
}

bool RunApplication::State::save(const std::string& path, std::string& message)
{
  try
  {
    const std::string resolved = resolve(path);
    if (path.empty() && own(settings.q_table_path))
      saveQTableFile(session.table(), settings.q_table_path);
    else
      saveQTableUnder(session.table(), settings.q_table_dir, path.empty() ? settings.q_table_path : path);
    message = "saved " + std::to_string(session.table().episodes) + " episodes, " +
              std::to_string(session.table().steps) + " steps of training to " + resolved;
    return true;
  }
  catch (const std::exception& e)  // QTableFileError, or anything else: never out of a service
  {
    message = std::string("nothing written: ") + e.what();
    return false;
  }
}

bool RunApplication::State::checkpoint(const std::string& finished_as, std::string& message)
{
  // The best table before the record that names it: a record never points at a best not on disk.
  if (best && best_episode != best_saved_episode)
  {
    try
    {
      saveQTableUnder(*best, settings.q_table_dir, run_folder + "/" + kRunBestTableFile);
      best_saved_episode = best_episode;
    }
    catch (const std::exception& e)  // QTableFileError, or anything else: never out of a service
    {
      message = std::string("nothing written: the best table: ") + e.what();
      return false;
    }
  }
  if (!save(run_folder + "/" + kRunTableFile, message))
    return false;
  if (best_saved_episode > 0)
  {
    run.best_episode = best_episode;
    run.best_worst_balanced = best_result.worstBalanced();
    run.best_robustness = best_result.summary();
  }
  run.episodes = session.table().episodes;
  run.steps = session.table().steps;
  run.recent_returns = session.recentReturns();
  run.finished = finished_as;
  try
  {
    writeFileUnder(settings.q_table_dir, run_folder + "/" + kRunRecordFile, formatRunRecord(run));
  }
  catch (const std::exception& e)
  {
    message +=
        ", but not its run record (a restart would go on from the previous checkpoint): " + std::string(e.what());
    return false;
  }
  return true;
}

void RunApplication::State::loadOnStart(LogLines& log)
{
  if (settings.load_on_start.empty())
  {
    if (!settings.learning)
      say(log, LogLine::Level::Warn, "evaluating a table of zeros (set ~load_on_start to a trained table)");
    return;
  }
  std::string path;
  try
  {
    const bool users_own = own(settings.load_on_start);
    path = users_own ? settings.load_on_start : resolve(settings.load_on_start);
    const std::string mismatch = install(users_own ? loadQTableFile(settings.load_on_start)
                                                   : loadQTableUnder(settings.q_table_dir, settings.load_on_start));
    if (!mismatch.empty())
      throw FileError(path + " does not fit this controller: " + mismatch);
  }
  catch (const FileError& e)
  {
    throw ConfigError("cannot start from the table '" + settings.load_on_start +
                      "' (~load_on_start, which the launch files' q_table or load argument sets): " + e.what());
  }
  say(log, LogLine::Level::Info,
      formatText("loaded %s (%llu episodes, %llu steps of training)", path.c_str(), count(session.table().episodes),
                 count(session.table().steps)));
}

void RunApplication::State::openStatsFile()
{
  const std::string& name = settings.stats_csv;
  if (name == "none" || name.empty())
    return;
  try
  {
    stats_file = std::make_unique<AppendingFile>(
        name.front() == '/' ? AppendingFile::open(name) : AppendingFile::openUnder(settings.q_table_dir, name));
  }
  catch (const FileError& e)
  {
    throw RunSettingError("stats_csv", "'" + name + "'", e.what());
  }
}

void RunApplication::State::openRun(const RunIdentity& previous, LogLines& log)
{
  run.run_id = settings.run_id;
  run.name_space = settings.name_space;
  run.seed = settings.seed;
  if (!settings.run_folder)
    return;
  // A respawn has the run id and the launcher of the process that started the run; a node
  // started by hand on a reused master has at most the id left there.
  if (!settings.run_id.empty() && previous.id == settings.run_id && previous.launcher == launcher &&
      !previous.folder.empty())
  {
    run_folder = previous.folder;
    resumeRun(true, log);
    return;
  }
  const std::time_t now = clocks.calendar();
  run.started = localTimeText(now);
  const std::string name = runFolderName(now, settings.name_space, settings.seed);
  // Made now, so that a folder that cannot be written is said at the start, not at the first
  // checkpoint; a name taken (another run started in the same second) gets a suffix. A run told
  // to write nothing along the way (no checkpoints, no save on shutdown) writes nothing yet.
  run_folder = name;
  try
  {
    for (int n = 2; writesAlong() && !makeDirectoryUnder(settings.q_table_dir, run_folder); ++n)
      run_folder = name + "_" + std::to_string(n);
    if (writesAlong())
      writeFileUnder(settings.q_table_dir, run_folder + "/" + kRunRecordFile, formatRunRecord(run));
  }
  catch (const FileError& e)
  {
    say(log, LogLine::Level::Error,
        formatText("cannot make this run's folder (%s): checkpoints will fail; ~save_q_table can still save the table "
                   "elsewhere",
                   e.what()));
  }
  say(log, LogLine::Level::Info,
      formatText("run %s: checkpoints go to %s", run_folder.c_str(),
                 resolve(run_folder + "/" + kRunTableFile).c_str()));
}

void RunApplication::State::resumeRun(bool respawn, LogLines& log)
{
  respawned = true;
  const char* restarted = respawn ? "restarted; " : "";
  const std::string table_path = run_folder + "/" + kRunTableFile;
  RunRecord record;
  QTable table;
  try
  {
    record = parseRunRecord(readFileUnder(settings.q_table_dir, run_folder + "/" + kRunRecordFile, 1 << 20));
    table = loadQTableUnder(settings.q_table_dir, table_path);
  }
  catch (const FileError& e)
  {
    if (!respawn)
      throw ConfigError("run " + run_folder + " has no checkpoint to go on from: " + e.what());
    // Killed before its first checkpoint (or the checkpoint is unusable): the run starts over.
    run.started = localTimeText(clocks.calendar());
    say(log, LogLine::Level::Warn,
        formatText("restarted; run %s has no checkpoint to go on from (%s): starting it over", run_folder.c_str(),
                   e.what()));
    return;
  }
  // A crash between the table's save and the record's leaves the record one checkpoint behind:
  // the table wins, and the solved window starts empty.
  const bool record_matches = record.episodes == table.episodes && record.steps == table.steps;
  const std::string mismatch =
      session.resume(std::move(table), record_matches ? record.recent_returns : std::vector<double>());
  if (!mismatch.empty())
    throw ConfigError(std::string(respawn ? "restarted, but the checkpoint " : "the checkpoint ") +
                      resolve(table_path) + " does not fit this controller's configuration: " + mismatch);
  run = record;
  const EpisodeSummary& s = session.lastEpisode();
  steps_at_last_episode = steps_at_last_progress = s.total_steps;
  say(log, LogLine::Level::Warn,
      formatText("%srun %s goes on from its checkpoint: episode %llu, %llu steps%s", restarted, run_folder.c_str(),
                 count(s.episode), count(s.total_steps),
                 record_matches ? "" : " (its record was one checkpoint behind: the solved window starts empty)"));
  if (record.finished.empty())
    restoreBest(log);
  else
  {
    // Ended (or killed) after its final save: nothing to train. A controller stays up rather
    // than exit, which under respawn would only start it again.
    finished = final_saved = true;
    say(log, LogLine::Level::Info,
        formatText("run %s has finished already (%s); nothing left to do", run_folder.c_str(),
                   record.finished.c_str()));
  }
}

void RunApplication::State::restoreBest(LogLines& log)
{
  if (run.best_episode == 0 || !suite || config.limits.suite_every == 0)
    return;
  const std::string path = run_folder + "/" + kRunBestTableFile;
  try
  {
    QTable table = loadQTableUnder(settings.q_table_dir, path);
    // Judged again rather than taken from the record: the same suite gives the same verdict (it
    // has its own seed), and a suite file changed since is then applied to both tables alike.
    best_result = evaluateSuite(table, config, *suite);
    best_episode = best_saved_episode = table.episodes;
    best = std::make_unique<QTable>(std::move(table));
  }
  catch (const std::exception& e)  // FileError, or a ConfigError: the table does not fit this configuration
  {
    say(log, LogLine::Level::Warn,
        formatText("the run's best table (episode %llu) cannot be used (%s): the best is looked for afresh",
                   count(run.best_episode), e.what()));
    run.best_episode = run.best_worst_balanced = 0;
    run.best_robustness.clear();
    return;
  }
  run.best_episode = best_episode;
  run.best_worst_balanced = best_result.worstBalanced();
  run.best_robustness = best_result.summary();
  say(log, LogLine::Level::Info,
      formatText("the best table so far is still the one to beat: episode %llu, worst case %llu balanced (%s)",
                 count(best_episode), count(best_result.worstBalanced()), resolve(path).c_str()));
}

void RunApplication::State::startStatsCsv(LogLines& log)
{
  const std::string& name = settings.stats_csv;
  if (name == "none" || (name.empty() && (!settings.learning || !settings.run_folder)))
    return;
  if (!stats_file)
  {
    // The run's own file: beside its checkpoints, made with its folder. A run told to write
    // nothing along the way (no checkpoints, no save on shutdown) makes that folder only when
    // there is something to write: here, at the first episode's end.
    if (!writesAlong() && !respawned && !csv_pending)
    {
      csv_pending = true;
      return;
    }
    try
    {
      if (csv_pending)
      {
        // Its folder is made now, under a name no other run has taken (as openRun does).
        const std::string base = run_folder;
        for (int n = 2; !makeDirectoryUnder(settings.q_table_dir, run_folder); ++n)
          run_folder = base + "_" + std::to_string(n);
        folder_made_late = true;
      }
      csv_pending = false;
      stats_file = std::make_unique<AppendingFile>(
          AppendingFile::openUnder(settings.q_table_dir, run_folder + "/" + kRunEpisodesFile));
    }
    catch (const FileError& e)
    {
      csv_pending = false;
      say(log, LogLine::Level::Error,
          std::string("no learning curve for this run (~stats_csv none silences this): ") + e.what());
      return;
    }
  }
  try
  {
    // A respawn goes on with its run's curve from the checkpoint it resumed (a run that starts
    // over keeps the header alone); anything else starts the curve afresh.
    csv = respawned ? std::make_unique<EpisodeCsvWriter>(std::move(*stats_file), session.episodesEnded())
                    : std::make_unique<EpisodeCsvWriter>(std::move(*stats_file));
  }
  catch (const FileError& e)
  {
    stats_file.reset();
    if (!name.empty())
      throw RunSettingError("stats_csv", "'" + name + "'", e.what());
    say(log, LogLine::Level::Error,
        std::string("no learning curve for this run (~stats_csv none silences this): ") + e.what());
    return;
  }
  stats_file.reset();
  say(log, LogLine::Level::Info,
      "one row per episode goes to " + csv->path() + " (rosrun cartpole_qlearning plot_learning_curve --follow " +
          csv->path() + ")");
}

void RunApplication::State::writeStatsRow(const std::string& robot, const EpisodeSummary& summary, LogLines& log)
{
  if (csv_pending)
    startStatsCsv(log);
  if (!csv)
    return;
  try
  {
    csv->write(summary, robot, clocks.unix_seconds());
  }
  catch (const FileError& e)
  {
    say(log, LogLine::Level::Error, std::string("the learning curve stops here: ") + e.what());
    csv.reset();
  }
}

void RunApplication::State::loadSuite(LogLines& log)
{
  const std::string& name = config.limits.suite;
  if (!settings.learning || name == "none")
    return;
  std::string where;
  if (name.front() == '/')
    suite_path = name;
  for (std::size_t i = 0; suite_path.empty() && i < settings.suite_folders.size(); ++i)
  {
    where += (where.empty() ? "" : ", ") + settings.suite_folders[i];
    if (std::ifstream(settings.suite_folders[i] + "/" + name).good())
      suite_path = settings.suite_folders[i] + "/" + name;
  }
  const bool needed = config.limits.suite_every > 0;
  try
  {
    if (suite_path.empty())
      throw ConfigError("training/suite = '" + name + "' is not allowed (no such file in " +
                        (where.empty() ? std::string("no folder") : where) + ")");
    suite = std::make_unique<RobustnessSuite>(loadRobustnessSuite(suite_path, config));
  }
  catch (const ConfigError& e)
  {
    if (needed)
      throw;
    say(log, LogLine::Level::Warn, std::string("this run will end without a robustness verdict: ") + e.what());
    return;
  }
  if (needed)
    say(log, LogLine::Level::Info,
        formatText("the robustness suite %s runs on the table every %llu episodes%s; the best table is kept",
                   suite_path.c_str(), count(config.limits.suite_every),
                   config.limits.until == TrainUntil::SuitePasses ? ", and training ends when it passes" : ""));
}

SuiteResult RunApplication::State::judge(std::uint64_t episode)
{
  SuiteResult result = evaluateSuite(session.table(), config, *suite);
  if (config.limits.suite_every > 0 && (!best || better(result, best_result)))
  {
    best = std::make_unique<QTable>(session.table());
    best_result = result;
    best_episode = episode;
  }
  return result;
}

void RunApplication::State::startClocks()
{
  started = last_episode_end = last_progress = clocks.steady();
}

RunApplication::RunApplication(RunSettings settings, const TrainingConfig& config, TrainingSession& session,
                               RunClocks clocks)
  : state_(std::make_unique<State>(std::move(settings), config, session, std::move(clocks)))
{
}

RunApplication::~RunApplication() = default;

LogLines RunApplication::start(const RunIdentity& previous, int launcher)
{
  State& s = *state_;
  LogLines log;
  s.launcher = launcher;
  s.loadSuite(log);
  s.loadOnStart(log);
  s.openStatsFile();
  if (s.settings.learning)
    s.openRun(previous, log);
  s.startStatsCsv(log);
  s.startClocks();
  return log;
}

LogLines RunApplication::resume(const std::string& folder)
{
  State& s = *state_;
  if (!s.settings.learning)
    throw ConfigError("a run is resumed to train it further, not to evaluate it");
  LogLines log;
  s.loadSuite(log);
  try
  {
    s.run_folder = relativePathUnder(s.settings.q_table_dir, folder);
  }
  catch (const FileError& e)
  {
    throw ConfigError("cannot resume the run '" + folder + "': " + e.what());
  }
  s.openStatsFile();
  s.resumeRun(false, log);
  s.startStatsCsv(log);
  s.startClocks();
  return log;
}

EpisodeEnd RunApplication::endEpisode(const std::string& robot, bool training_finished)
{
  State& st = *state_;
  EpisodeEnd end;
  const EpisodeSummary& s = st.session.lastEpisode();
  // Before any checkpoint: a row is never missing from a run that a respawn resumes from there.
  st.writeStatsRow(robot, s, end.log);
  if (st.folder_made_late)
  {
    st.folder_made_late = false;
    end.run_folder = st.run_folder;
  }
  const auto now = st.clocks.steady();
  const auto robot_end = st.robot_last_end.emplace(robot, st.started).first;
  const double wall = seconds(now - st.last_episode_end);
  const double robot_wall = seconds(now - robot_end->second);
  st.last_episode_end = robot_end->second = now;
  end.steps_per_second = wall > 0.0 ? static_cast<double>(s.total_steps - st.steps_at_last_episode) / wall : 0.0;
  end.robot_steps_per_second = robot_wall > 0.0 ? s.steps / robot_wall : 0.0;
  st.steps_at_last_episode = s.total_steps;

  // The suite at its cadence (and at the end): on a copy of the table, the best one kept.
  const TrainingLimits& limits = st.config.limits;
  const bool until_suite = limits.until == TrainUntil::SuitePasses;
  std::unique_ptr<SuiteResult> verdict;
  if (st.settings.learning && st.suite && limits.suite_every > 0 &&
      (s.episode % limits.suite_every == 0 || training_finished))
  {
    verdict = std::make_unique<SuiteResult>(st.judge(s.episode));
    say(end.log, LogLine::Level::Info,
        formatText("robustness at episode %llu (%llu steps): %s", count(s.episode), count(s.total_steps),
                   verdict->summary().c_str()));
    training_finished = training_finished || (until_suite && verdict->passed());
  }
  if (st.settings.learning && training_finished && st.suite)
  {
    if (st.best && better(st.best_result, *verdict))
    {
      // The best table seen is what the run saves (and what the session holds from now on).
      say(end.log, LogLine::Level::Info,
          formatText("keeping the table of episode %llu (worst case %llu balanced) over the last one (%llu)",
                     count(st.best_episode), count(st.best_result.worstBalanced()), count(verdict->worstBalanced())));
      st.session.replaceTable(*st.best);
      *verdict = st.best_result;
    }
    if (!verdict)
      verdict = std::make_unique<SuiteResult>(evaluateSuite(st.session.table(), st.config, *st.suite));
    end.robustness = st.run.robustness = verdict->summary();
    end.log.push_back({LogLine::Level::Info,
                        formatText("robustness of the saved table (%s, greedy, %llu episodes per case):\n",
                                   st.suite_path.c_str(), count(st.suite->episodes)) +
                            verdict->table(),
                        false});
  }
  const bool passed = verdict && verdict->passed();
  const bool done_well = until_suite ? passed : s.solved;
  const char* finished_as = !done_well ? "max_episodes" : until_suite ? "suite_passed" : "solved";

  // When training ends here, the table is saved before the caller says so: whoever acts on the
  // last episode_stats finds the final file. Into the run's folder; a solved run (under until
  // suite_passes: one whose suite passed) also replaces the default table (the one
  // evaluate.launch loads), any other leaves it as it was.
  std::string saved;
  bool saved_ok = true;
  if (training_finished)
  {
    // The default table first: a crash between the two saves then leaves a run not yet marked
    // finished, which a respawn finishes again.
    std::string published;
    const bool publishes = done_well && !st.settings.q_table_path.empty();
    const bool published_ok = publishes && st.save("", published);
    if (st.settings.run_folder)
      saved_ok = st.checkpoint(finished_as, saved);
    else
    {
      // The default table is the only save, if there is one.
      saved = "no run folder";
      saved_ok = !publishes || published_ok;
    }
    st.final_saved = saved_ok || published_ok;
    if (publishes)
      saved += published_ok ? "; the default table: " + published : "; BUT NOT the default table: " + published;
    else if (!st.settings.q_table_path.empty())
      saved += "; the default table " + st.resolve("") + " is left as it was (this run did not " +
               (until_suite ? "pass the suite" : "solve") + ": ~save_q_table saves it there if you want it)";
  }

  if (st.settings.trace && st.settings.learning)
  {
    const std::string which = st.session.robots() > 1 ? robot + "'s episode " + std::to_string(s.robot_episode) + " (" +
                                                            std::to_string(s.episode) + " in all)"
                                                      : "episode " + std::to_string(s.episode);
    end.log.push_back(
        {LogLine::Level::Info, "Q-table after " + which + ":\n" + qTableText(st.session.table(), st.state_names), false});
  }

  if (limits.progress_every > 0 && s.episode % limits.progress_every == 0)
  {
    const double interval = seconds(now - st.last_progress);
    const double rate =
        interval > 0.0 ? static_cast<double>(s.total_steps - st.steps_at_last_progress) / interval : 0.0;
    end.log.push_back(
        {LogLine::Level::Info, progressLine(s, st.config.task.solved_window, rate, seconds(now - st.started)), false});
    st.steps_at_last_progress = s.total_steps;
    st.last_progress = now;
  }

  if (!st.settings.learning)
  {
    // Evaluation: every episode said, and after evaluation_episodes a one-line verdict.
    st.balanced += s.truncated && !s.terminated;
    say(end.log, LogLine::Level::Info,
        formatText("evaluation episode %llu: %u steps, return %.1f, %s", count(s.episode), s.steps, s.episode_return,
                   s.terminated ? "fell" : "balanced to the step limit"));
    if (st.settings.evaluation_episodes == 0 || s.episode < st.settings.evaluation_episodes)
      return end;
    std::string verdict = formatText(
        "EVALUATED %llu episodes: %llu balanced to the step limit (%u steps), mean return %.1f", count(s.episode),
        count(st.balanced), st.config.task.max_episode_steps, shownReturn(s.mean_return_window, 1));
    if (!st.settings.evaluation_case.empty())
      verdict += formatText("; %s: %s (needs %llu)", st.settings.evaluation_case.c_str(),
                            st.balanced >= st.settings.evaluation_pass ? "PASSED" : "FAILED",
                            count(st.settings.evaluation_pass));
    say(end.log, LogLine::Level::Info, verdict);
    st.finished = end.finished = true;
    return end;
  }
  if (training_finished)
  {
    st.finished = true;
    if (!saved_ok)
    {
      // Keep the trained table alive: the user can still save it elsewhere with ~save_q_table.
      say(end.log, LogLine::Level::Error,
          formatText("training ended (%s, episode %llu) but the table could not be saved: %s. The node keeps running: "
                     "call ~save_q_table with another path",
                     finished_as, count(s.episode), saved.c_str()));
      return end;
    }
    say(end.log, LogLine::Level::Info,
        formatText("%s after %llu episodes, %llu steps, %.1f s (mean return of the last %u: %.2f); %s",
                   until_suite ? (passed ? "SUITE PASSED" : "suite NOT passed, max_episodes reached")
                   : s.solved  ? "SOLVED"
                               : "NOT solved, max_episodes reached",
                   count(s.episode), count(s.total_steps), seconds(now - st.started), st.config.task.solved_window,
                   shownReturn(s.mean_return_window, 2), saved.c_str()));
    end.finished = true;
    return end;
  }
  if (st.settings.checkpoint_every > 0 && s.episode % st.settings.checkpoint_every == 0)
  {
    std::string message;
    if (st.checkpoint("", message))
      say(end.log, LogLine::Level::Info, "checkpoint: " + message);
    else
      say(end.log, LogLine::Level::Warn, "checkpoint failed: " + message);
  }
  return end;
}

ServiceAnswer RunApplication::save(const std::string& path)
{
  ServiceAnswer answer;
  answer.success = state_->save(path, answer.message);
  say(answer.log, answer.success ? LogLine::Level::Info : LogLine::Level::Warn, "save_q_table: " + answer.message);
  return answer;
}

ServiceAnswer RunApplication::load(const std::string& path)
{
  State& s = *state_;
  ServiceAnswer answer;
  try
  {
    const std::string resolved = s.resolve(path);
    QTable table = path.empty() && s.own(s.settings.q_table_path)
                       ? loadQTableFile(s.settings.q_table_path)
                       : loadQTableUnder(s.settings.q_table_dir, path.empty() ? s.settings.q_table_path : path);
    const std::uint64_t episodes = table.episodes;
    const std::uint64_t steps = table.steps;
    const std::string mismatch = s.install(std::move(table));
    if (!mismatch.empty())
      throw FileError(resolved + " does not fit this controller: " + mismatch);
    answer.success = true;
    answer.message = "loaded " + resolved + " (" + std::to_string(episodes) + " episodes, " + std::to_string(steps) +
                     " steps of training)";
    say(answer.log, LogLine::Level::Info, "load_q_table: " + answer.message);
    if (s.settings.learning && s.csv)
    {
      // Training goes on from the loaded table's episode count; the curve follows it.
      try
      {
        s.csv->startOver();
        say(answer.log, LogLine::Level::Info,
            formatText("the learning curve %s starts over from the loaded table's episode %llu", s.csv->path().c_str(),
                       count(episodes)));
      }
      catch (const FileError& e)
      {
        say(answer.log, LogLine::Level::Warn, std::string(e.what()) + "; the learning curve stops here");
        s.csv.reset();
      }
    }
  }
  catch (const std::exception& e)  // QTableFileError, or anything else: never out of a service
  {
    answer.success = false;
    answer.message = std::string("refused, the table in use is unchanged: ") + e.what();
    answer.log.clear();
    say(answer.log, LogLine::Level::Warn, "load_q_table: " + answer.message);
  }
  return answer;
}

LogLines RunApplication::shutdown()
{
  State& s = *state_;
  LogLines log;
  if (s.shut_down || !s.settings.learning || !s.settings.save_on_shutdown || s.final_saved)
    return log;
  s.shut_down = true;
  std::string message;
  const bool ok = s.checkpoint("", message);
  say(log, ok ? LogLine::Level::Info : LogLine::Level::Error,
      "on shutdown: " + message + " (the default table is left as it was)");
  return log;
}

RunIdentity RunApplication::identity() const
{
  if (!state_->settings.learning || state_->settings.run_id.empty())
    return {};
  return {state_->settings.run_id, state_->launcher, state_->run_folder};
}

bool RunApplication::respawned() const
{
  return state_->respawned;
}

bool RunApplication::finished() const
{
  return state_->finished;
}

EvaluationVerdict RunApplication::verdict() const
{
  EvaluationVerdict verdict;
  if (state_->settings.learning)
    return verdict;
  verdict.episodes = state_->session.episodesEnded();
  verdict.balanced = state_->balanced;
  verdict.mean_return = verdict.episodes > 0 ? state_->session.lastEpisode().mean_return_window : 0.0;
  return verdict;
}

std::string RunApplication::resolve(const std::string& path) const
{
  return state_->resolve(path);
}

const std::string& RunApplication::tableDirectory() const
{
  return state_->settings.q_table_dir;
}

const std::string& RunApplication::runFolder() const
{
  return state_->run_folder;
}

}  // namespace cartpole_qlearning
