#include "cartpole_qlearning/application/run_application.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/table_config.h"
#include "cartpole_qlearning/learning/trace.h"

#include <chrono>
#include <functional>
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

void append(LogLines& log, const LogLines& more)
{
  log.insert(log.end(), more.begin(), more.end());
}

// What the default table held before a run replaces it (a solved table replaced by the next run's,
// the tutorial's by a robust run's), said beside the save; "" when there was none to read.
std::string replacedTableText(const TableStore& tables)
{
  try
  {
    const QTable before = tables.load("");
    return formatText(", replacing the one there (%llu episodes, %llu steps)", count(before.episodes),
                      count(before.steps));
  }
  catch (const std::exception&)  // none there yet, or not a table: nothing to say it replaced
  {
    return "";
  }
}
}  // namespace

struct RunApplication::Parts
{
  Parts(RunSettings settings_, const TrainingConfig& config_, TrainingSession& session_, RunClocks clocks)
    : settings(std::move(settings_)),
      config(config_),
      session(session_),
      tables(settings.q_table_dir, settings.q_table_path,
             settings.own_absolute_paths ? AbsolutePaths::AreTheUsersFiles : AbsolutePaths::MustLieInTheFolder),
      folder(settings, tables, std::move(clocks.calendar)),
      curve(settings, folder, std::move(clocks.unix_seconds)),
      keeper(config, settings.learning(), settings.suite_folders, settings.controlling(), settings.names),
      meters(config, settings, clocks.steady),
      steady(std::move(clocks.steady))
  {
    if (settings.trace && settings.learning())
      state_names = stateNames(config.agent);
    // Every table this run saves (the services, checkpoints, the final and shutdown saves, the
    // best table) then says what it takes to run it.
    session.stampTables(config.physics.tau, trainingConfigText(config));
    // The node's and train_headless's settings refuse a prediction while learning: this is a backstop.
    const std::string refused = session.predictDelay(config.physics, settings.predict_delay_steps);
    if (!refused.empty())
      throw std::invalid_argument(refused);
  }

  // Puts a loaded table in use. Training goes on with the table's counts: episode numbers,
  // steps, the schedules and max_episodes all count from them, so the progress lines and the
  // saves agree (the solved window starts empty). Evaluation counts its own episodes from 1.
  // Returns what does not fit (nothing changed then).
  std::string useTable(QTable table);
  void loadOnStart(LogLines& log);
  void opened(RunOpening opening, LogLines& log);
  // Training ends at this episode: the final saves. Returns what was saved (or why not) for the
  // final line; saved_ok false when the table could not be kept.
  std::string saveFinal(bool done_well, const char* finished_as, bool& saved_ok);
  void endTraining(const EpisodeSummary& s, bool passed, const char* finished_as, bool saved_ok,
                   const std::string& saved, EpisodeEnd& end);

  RunSettings settings;
  TrainingConfig config;
  TrainingSession& session;
  TableStore tables;
  RunFolder folder;
  LearningCurve curve;
  BestTableKeeper keeper;
  RunMeters meters;
  std::function<std::chrono::steady_clock::time_point()> steady;  // times the final verdict
  std::vector<std::string> state_names;                           // as the trace names the rows
  // A table to load has this run's shape (useTable refuses any other): its file is at most this
  // long. Fixed for the run, so readTable() reads it without a lock. (After session: initialised
  // from it.)
  const std::uint64_t load_bytes_limit =
      maxQTableFileBytes(session.table().stateCount(), session.table().actionCount());
  // The run's table's shape, for copies made apart from the table in use. Fixed, as above.
  const FeatureParams features = session.table().features();
  const std::vector<double> actions = session.table().actions();

  int launcher = 0;
  // The first episode whose window was solved in this session (0: none yet). A run that goes on
  // after solved (training/stop_when_solved false) says when it solved.
  std::uint64_t first_solved = 0;
  bool finished = false;
  bool final_saved = false;  // training ended and its table is saved (else a shutdown saves it)
  bool shut_down = false;
};

std::string RunApplication::Parts::useTable(QTable table)
{
  const std::string mismatch =
      settings.learning() ? session.resume(std::move(table), {}) : session.replaceTable(std::move(table));
  meters.countStepsFrom(session.lastEpisode().total_steps);
  return mismatch;
}

void RunApplication::Parts::loadOnStart(LogLines& log)
{
  if (settings.load_on_start.empty())
  {
    if (!settings.learning())
      say(log, LogLine::Level::Warn,
          "evaluating a table of zeros (set " + settings.names(Setting::LoadOnStart) + " to a trained table)");
    return;
  }
  std::string path;
  try
  {
    path = tables.resolve(settings.load_on_start);
    QTable table = tables.load(settings.load_on_start);
    // Named with both sources: which of the two is not what the user meant is theirs to say.
    const std::string contradiction = tableContradiction(config, settings.config_origin, table, path);
    if (!contradiction.empty())
      throw FileError(contradiction);
    const std::string mismatch = useTable(std::move(table));
    if (!mismatch.empty())
      throw FileError(path + " does not fit this controller: " + mismatch);
  }
  catch (const FileError& e)
  {
    // Where the table came from, unless the front end says it before the message.
    const std::string origin = settings.names(Setting::LoadOnStartOrigin);
    throw ConfigError("cannot start from the table '" + settings.load_on_start + "'" +
                      (origin.empty() ? "" : " (" + origin + ")") + ": " + e.what());
  }
  if (!settings.config_warning.empty())
    say(log, LogLine::Level::Warn, settings.config_warning);
  say(log, LogLine::Level::Info,
      formatText("loaded %s (%llu episodes, %llu steps of training)", path.c_str(), count(session.table().episodes),
                 count(session.table().steps)));
}

void RunApplication::Parts::opened(RunOpening opening, LogLines& log)
{
  if (opening == RunOpening::GoesOn)
    append(log, keeper.restore(folder));
  else if (opening == RunOpening::FinishedAlready)
    finished = final_saved = true;
}

std::string RunApplication::Parts::saveFinal(bool done_well, const char* finished_as, bool& saved_ok)
{
  // Into the run's folder; a run done well (solved, or under until suite_passes: its suite
  // passed) also replaces the default table (the one evaluate.launch loads), any other leaves it
  // as it was. The default table first: a crash between the two saves then leaves a run not yet
  // marked finished, which a respawn finishes again.
  const bool publishes = done_well && !settings.q_table_path.empty();
  const std::string save_service = settings.names(Setting::SaveService);
  const std::string replaced = publishes ? replacedTableText(tables) : "";
  const ServiceAnswer published = publishes ? tables.serveSave(session.table(), "") : ServiceAnswer{};
  std::string saved;
  saved_ok = true;
  if (settings.run_folder)
    saved_ok = folder.checkpoint(session, finished_as, keeper.best(), saved);
  else
  {
    // The default table is the only save, if there is one.
    saved = !settings.q_table_path.empty()
                ? "no run folder"
                : "no run folder and no " + settings.names(Setting::TablePath) + ": the table was not written";
    saved_ok = !publishes || published.success;
  }
  final_saved = saved_ok || published.success;
  if (publishes)
    saved += (published.success ? "; the default table: " + published.message + replaced
                                : "; BUT NOT the default table: " + published.message);
  else if (!settings.q_table_path.empty())
    saved += "; the default table " + tables.resolveForService("") + " is left as it was (this run did not " +
             (config.limits.until == TrainUntil::SuitePasses ? "pass the suite" : "solve") +
             (!save_service.empty() ? ": " + save_service + " saves it there if you want it)"
              : settings.run_folder ? std::string(": copy the run's table there if you want it)")
                                    : std::string("; with no run folder its table is not kept)"));
  return saved;
}

void RunApplication::Parts::endTraining(const EpisodeSummary& s, bool passed, const char* finished_as, bool saved_ok,
                                        const std::string& saved, EpisodeEnd& end)
{
  finished = true;
  if (!saved_ok)
  {
    // Keep the trained table alive: the user can still save it elsewhere through the save
    // service; with none, the same seed trains it again.
    const SettingNames& names = settings.names;
    const std::string save_service = names(Setting::SaveService);
    const std::string what_now = !save_service.empty()
                                     ? "The node keeps running: call " + save_service + " with another path"
                                     : "The same " + names(Setting::Seed) + " trains the same table again: give " +
                                           names(Setting::TablePath) + ", or the table folder (" +
                                           names(Setting::TableFolder) + "), a place that can be written";
    say(end.log, LogLine::Level::Error,
        formatText("training ended (%s, episode %llu) but the table could not be saved: %s. %s", finished_as,
                   count(s.episode), saved.c_str(), what_now.c_str()));
    return;
  }
  const bool until_suite = config.limits.until == TrainUntil::SuitePasses;
  // A run that went on after solving says when it solved and what its window holds now.
  const bool went_on = config.limits.goesOnAfterSolved() && first_solved > 0;
  const std::string outcome =
      until_suite ? (passed ? "SUITE PASSED" : "suite NOT passed, max_episodes reached")
      : went_on   ? formatText("SOLVED at episode %llu, went on: max_episodes reached", count(first_solved))
      : s.solved  ? "SOLVED"
                  : "NOT solved, max_episodes reached";
  std::string window =
      formatText("mean return of the last %u: %.2f", config.task.solved_window, shownReturn(s.mean_return_window, 2));
  if (went_on)
    window += s.solved ? ", still solved" : formatText(", below %g now", config.task.solved_mean_return);
  const RewardScheme score = config.task.scoreReward();
  if (score != RewardScheme::Gymnasium)
    window += "; " + toString(score) + "'s reward: " + rewardMeaning(score);
  if (config.task.solved_reward && *config.task.solved_reward != config.task.reward)
    window += " (trained on " + toString(config.task.reward) + "'s)";
  say(end.log, LogLine::Level::Info,
      formatText("%s after %llu episodes, %llu steps, %.1f s (%s); %s", outcome.c_str(), count(s.episode),
                 count(s.total_steps), meters.secondsRunning(), window.c_str(), saved.c_str()));
  end.finished = true;
}

RunApplication::RunApplication(RunSettings settings, const TrainingConfig& config, TrainingSession& session,
                               RunClocks clocks)
  : parts_(std::make_unique<Parts>(std::move(settings), config, session, std::move(clocks)))
{
}

RunApplication::~RunApplication() = default;

LogLines RunApplication::start(const RunIdentity& previous, int launcher)
{
  Parts& p = *parts_;
  LogLines log = p.keeper.loadSuite();
  p.launcher = launcher;
  p.loadOnStart(log);
  if (p.settings.controlling())
    append(log, p.keeper.judgeBeforeControl(p.session.table(), p.settings.predict_delay_steps));
  p.curve.openUsersFile();
  if (p.settings.learning())
    p.opened(p.folder.open(previous, launcher, p.session, log), log);
  p.curve.start(p.session.episodesEnded(), log);
  p.meters.start(p.session.lastEpisode().total_steps);
  return log;
}

void RunApplication::checkStart()
{
  Parts& p = *parts_;
  LogLines log = p.keeper.loadSuite();
  p.loadOnStart(log);
}

LogLines RunApplication::resume(const std::string& folder)
{
  Parts& p = *parts_;
  if (!p.settings.learning())
    throw ConfigError("a run is resumed to train it further, not to evaluate it");
  LogLines log = p.keeper.loadSuite();
  p.folder.selectForResume(folder);
  p.curve.openUsersFile();
  p.opened(p.folder.resume(p.session, log), log);
  p.curve.start(p.session.episodesEnded(), log);
  p.meters.start(p.session.lastEpisode().total_steps);
  return log;
}

EpisodeEnd RunApplication::endEpisode(const std::string& robot, bool training_finished)
{
  Parts& p = *parts_;
  EpisodeEnd end;
  const EpisodeSummary& s = p.session.lastEpisode();
  // Before any checkpoint: a row is never missing from a run that a respawn resumes from there.
  p.curve.write(robot, s, end.log);
  end.run_folder = p.folder.takeNewName();
  const RunMeters::Rates rates = p.meters.episodeEnded(robot, s);
  end.steps_per_second = rates.steps_per_second;
  end.robot_steps_per_second = rates.robot_steps_per_second;

  const bool until_suite = p.config.limits.until == TrainUntil::SuitePasses;
  if (p.settings.learning() && s.solved && p.first_solved == 0)
  {
    p.first_solved = s.episode;
    // A run that goes on after solving says so when it happens, not only at its end.
    if (p.config.limits.goesOnAfterSolved() && !training_finished)
      say(end.log, LogLine::Level::Info,
          formatText("solved at episode %llu (mean return of the last %u: %.2f); training goes on to max_episodes",
                     count(s.episode), p.config.task.solved_window, shownReturn(s.mean_return_window, 2)));
  }
  std::optional<SuiteResult> verdict = p.keeper.evaluateWhenDue(p.session, training_finished, end.log);
  training_finished = training_finished || (until_suite && verdict && verdict->passed());
  if (training_finished && p.keeper.hasSuite())
  {
    const auto verdict_began = p.steady();
    verdict = p.keeper.settle(p.session, verdict, end.log);
    end.verdict_seconds = std::chrono::duration<double>(p.steady() - verdict_began).count();
    end.robustness = verdict->summary();
    p.folder.setRobustness(end.robustness);
  }
  const bool passed = verdict && verdict->passed();
  const bool done_well = until_suite ? passed : s.solved;
  // Where training was going: solved, the suite passed, or (going on after solved) max_episodes.
  end.goal_reached = training_finished && (p.config.limits.goesOnAfterSolved() || done_well);
  const char* finished_as = !done_well ? "max_episodes" : until_suite ? "suite_passed" : "solved";

  // When training ends here, the table is saved before the caller says so: whoever acts on the
  // last episode_stats finds the final file.
  bool saved_ok = true;
  const std::string saved = training_finished ? p.saveFinal(done_well, finished_as, saved_ok) : "";

  if (p.settings.trace && p.settings.learning())
  {
    const std::string which = p.session.robots() > 1 ? robot + "'s episode " + std::to_string(s.robot_episode) + " (" +
                                                           std::to_string(s.episode) + " in all)"
                                                     : "episode " + std::to_string(s.episode);
    end.log.push_back(
        {LogLine::Level::Info, "Q-table after " + which + ":\n" + qTableText(p.session.table(), p.state_names), false});
  }
  p.meters.addProgress(s, end.log);

  if (!p.settings.learning())
  {
    // Evaluation: every episode said, and after evaluation_episodes a one-line verdict. (Control:
    // an episode ends with a fall, which its ControlMeter says.)
    if (!p.settings.controlling() && p.meters.addEvaluationEpisode(s, end.log))
      p.finished = end.finished = true;
    return end;
  }
  if (training_finished)
    p.endTraining(s, passed, finished_as, saved_ok, saved, end);
  else if (p.settings.checkpoint_every > 0 && s.episode % p.settings.checkpoint_every == 0)
  {
    std::string message;
    if (p.folder.checkpoint(p.session, "", p.keeper.best(), message))
      say(end.log, LogLine::Level::Info, "checkpoint: " + message);
    else
      say(end.log, LogLine::Level::Warn, "checkpoint failed: " + message);
  }
  return end;
}

ServiceAnswer RunApplication::save(const std::string& path)
{
  QTable copy = tableOfThisShape();
  copyTableInto(copy);
  return saveCopy(copy, path);
}

ServiceAnswer RunApplication::load(const std::string& path)
{
  return useTable(readTable(path));
}

QTable RunApplication::tableOfThisShape() const
{
  return QTable(parts_->features, parts_->actions);
}

void RunApplication::copyTableInto(QTable& copy) const
{
  // Same shape: the assignment copies the values into the memory the copy has (no allocation).
  copy = parts_->session.table();
}

ServiceAnswer RunApplication::saveCopy(const QTable& copy, const std::string& path) const
{
  return parts_->tables.serveSave(copy, path);
}

TableRead RunApplication::readTable(const std::string& path) const
{
  return parts_->tables.readForService(path, parts_->load_bytes_limit);
}

ServiceAnswer RunApplication::useTable(TableRead read)
{
  Parts& p = *parts_;
  std::uint64_t episodes = 0;
  ServiceAnswer answer = p.tables.useForService(std::move(read), [&](QTable table) {
    episodes = table.episodes;
    return p.useTable(std::move(table));
  });
  // Training goes on from the loaded table's episode count; the curve follows it.
  if (answer.success)
    p.curve.startOver(episodes, answer.log);
  return answer;
}

LogLines RunApplication::shutdown()
{
  Parts& p = *parts_;
  LogLines log;
  if (p.shut_down || !p.settings.learning() || !p.settings.save_on_shutdown || p.final_saved)
    return log;
  p.shut_down = true;
  std::string message;
  const bool ok = p.folder.checkpoint(p.session, "", p.keeper.best(), message);
  say(log, ok ? LogLine::Level::Info : LogLine::Level::Error,
      "on shutdown: " + message + " (the default table is left as it was)");
  return log;
}

RunIdentity RunApplication::identity() const
{
  if (!parts_->settings.learning() || parts_->settings.run_id.empty())
    return {};
  return {parts_->settings.run_id, parts_->launcher, parts_->folder.name()};
}

bool RunApplication::respawned() const
{
  return parts_->folder.resumed();
}

bool RunApplication::finished() const
{
  return parts_->finished;
}

EvaluationVerdict RunApplication::verdict() const
{
  if (parts_->settings.learning())
    return {};
  return parts_->meters.verdict(parts_->session);
}

std::string RunApplication::resolve(const std::string& path) const
{
  return parts_->tables.resolveForService(path);
}

const std::string& RunApplication::tableDirectory() const
{
  return parts_->settings.q_table_dir;
}

const std::string& RunApplication::runFolder() const
{
  return parts_->folder.name();
}

}  // namespace cartpole_qlearning
