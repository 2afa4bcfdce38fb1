#include "cartpole_qlearning/application/best_table_keeper.h"

#include <algorithm>
#include <fstream>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
unsigned long long count(std::uint64_t value)
{
  return static_cast<unsigned long long>(value);
}

// A table that passes beats one that does not; then the more balanced in its worst case.
bool better(const SuiteResult& a, const SuiteResult& b)
{
  return std::make_pair(a.passed(), a.worstBalanced()) > std::make_pair(b.passed(), b.worstBalanced());
}

// How to find out, case by case and as soon as it is decided, whether a table can beat `best`
// (a whole verdict): beating it takes every case at its target. Against a passing best, a table
// must pass and balance more than its worst case (pass and worst + 1, the larger); against a
// failing one, pass or balance more than its worst case, which takes at least the smaller of the
// two in every case. So every table that better() would rank above the best reaches its targets,
// and most tables stop at their first case short of one, after a few episodes of it.
SuiteRun againstTheBest(const SuiteResult& best, std::vector<std::size_t> order)
{
  SuiteRun run = SuiteRun::untilDecided(std::move(order));
  const std::uint64_t above = best.worstBalanced() + 1;
  const bool passing = best.passed();
  run.target = [above, passing](const SuiteCase& c) {
    return passing ? std::max(c.pass, above) : std::min(c.pass, above);
  };
  return run;
}
}  // namespace

BestTableKeeper::BestTableKeeper(const TrainingConfig& config, bool learning, std::vector<std::string> suite_folders,
                                 bool control, SettingNames names)
  : config_(config),
    learning_(learning),
    control_(control),
    suite_folders_(std::move(suite_folders)),
    names_(std::move(names))
{
}

LogLines BestTableKeeper::loadSuite()
{
  LogLines log;
  const std::string& name = config_.limits.suite;
  if (!(learning_ || control_) || name == "none")
    return log;
  std::string where;
  if (name.front() == '/')
    suite_path_ = name;
  for (std::size_t i = 0; suite_path_.empty() && i < suite_folders_.size(); ++i)
  {
    where += (where.empty() ? "" : ", ") + suite_folders_[i];
    if (std::ifstream(suite_folders_[i] + "/" + name).good())
      suite_path_ = suite_folders_[i] + "/" + name;
  }
  const bool needed = learning_ && config_.limits.suite_every > 0;
  try
  {
    if (suite_path_.empty())
      throw ConfigError("training/suite = '" + name + "' is not allowed (no such file in " +
                        (where.empty() ? std::string("no folder") : where) + ")");
    suite_ = std::make_unique<RobustnessSuite>(loadRobustnessSuite(suite_path_, config_));
    order_.clear();
    falls_ = FallenEpisodes();
    for (std::size_t i = 0; i < suite_->cases.size(); ++i)
      order_.push_back(i);
  }
  catch (const ConfigError& e)
  {
    if (needed)
      throw;
    log.push_back(
        {LogLine::Level::Warn, std::string(learning_ ? "this run will end without a robustness verdict: "
                                                     : "no robustness verdict on the table before control: ") +
                                   e.what()});
    return log;
  }
  if (needed)
  {
    const std::string when = config_.limits.suite_every == 1
                                 ? std::string("after every episode")
                                 : formatText("every %llu episodes", count(config_.limits.suite_every));
    log.push_back(
        {LogLine::Level::Info,
         formatText("the robustness suite %s runs on the table %s%s; the best table is kept", suite_path_.c_str(),
                    when.c_str(),
                    config_.limits.until == TrainUntil::SuitePasses ? ", and training ends when it passes" : "")});
  }
  return log;
}

LogLines BestTableKeeper::judgeBeforeControl(const QTable& table, unsigned predict_delay_steps) const
{
  LogLines log;
  if (!suite_)
    return log;
  SuiteRun how = SuiteRun::untilDecided(order_);
  how.stop_at_first_failure = true;
  how.predict_delay_steps = predict_delay_steps;
  const SuiteResult result = evaluateSuite(table, config_, *suite_, how);
  if (result.passed())
    log.push_back({LogLine::Level::Info, formatText("the table passes the robustness suite %s (%zu cases)",
                                                    suite_path_.c_str(), suite_->cases.size())});
  else
    log.push_back({LogLine::Level::Warn,
                   formatText("this table FAILS the robustness suite %s: %s. It was not shown to hold a robot that "
                              "differs from its model (a late command, noise, other masses, pushes): watch the robot",
                              suite_path_.c_str(), result.summary().c_str())});
  return log;
}

std::optional<SuiteResult> BestTableKeeper::evaluateWhenDue(const TrainingSession& session, bool training_ends,
                                                            LogLines& log)
{
  const EpisodeSummary& s = session.lastEpisode();
  if (!evaluatesDuringTraining() || (s.episode % config_.limits.suite_every != 0 && !training_ends))
    return std::nullopt;
  // Against the best so far first, each case only until it is decided whether this table can beat
  // it: most cannot, and that result (a verdict cut short, said plainly) is this evaluation's. A
  // table that can is evaluated whole and compared on whole verdicts, as every table was: with
  // best_every 0 the table kept is the one whole evaluations of every table would keep. (The
  // suite runs greedily on the table, learning nothing.)
  // Between the evaluations that look for the best (training/best_every), only whether the table
  // passes: each case stops at the fall that fails it, far sooner than at the one that says it
  // cannot beat a best near the pass marks; a table that passes is judged whole below, as before.
  // Against a passing best, beating it asks more than passing: always ranked then.
  const bool passing_decides = config_.limits.until == TrainUntil::SuitePasses && best_ && best_->result.passed();
  const std::uint64_t best_every = config_.limits.best_every;
  const bool ranks =
      best_every == 0 || s.episode % best_every == 0 || training_ends || (best_ && best_->result.passed());
  // Where the cut-short evaluation left each case: a table judged whole below goes on from there.
  SuiteProgress progress;
  if (best_ && !passing_decides)
  {
    SuiteRun how = ranks ? againstTheBest(best_->result, order_) : SuiteRun::untilDecided(order_);
    how.falls = &falls_;
    how.progress = &progress;
    SuiteResult quick = evaluateSuite(session.table(), config_, *suite_, how);
    failedCaseFirst(order_, quick, *suite_);
    if (!quick.reachedTargets())
    {
      // Judged after every episode, a run has thousands of these: one line in each stretch of
      // progress_every episodes (and at the end) says how many there were, and every table that
      // could beat the best has a line of its own below.
      const std::uint64_t every = config_.limits.progress_every;
      if (training_ends || (every > 0 && s.episode / every > progress_said_))
      {
        log.push_back(
            {LogLine::Level::Info,
             formatText("robustness at episode %llu (%llu steps): %s; %s (episode %llu, worst case %llu "
                        "balanced)%s",
                        count(s.episode), count(s.total_steps), quick.summary().c_str(),
                        ranks ? "no better than the best so far" : "does not pass; the best so far",
                        count(best_->episode), count(best_->result.worstBalanced()), othersNotKept().c_str())});
        if (every > 0)
          progress_said_ = s.episode / every;
      }
      else
        ++not_kept_unsaid_;
      return quick;
    }
  }
  SuiteRun whole = SuiteRun::complete();
  whole.progress = &progress;
  SuiteResult result = evaluateSuite(session.table(), config_, *suite_, whole);
  if (!best_ || better(result, best_->result))
    best_ = BestTable{session.table(), result, s.episode};
  log.push_back(
      {LogLine::Level::Info, formatText("robustness at episode %llu (%llu steps): %s%s", count(s.episode),
                                        count(s.total_steps), result.summary().c_str(), othersNotKept().c_str())});
  return result;
}

std::string BestTableKeeper::othersNotKept()
{
  const std::uint64_t others = not_kept_unsaid_;
  not_kept_unsaid_ = 0;
  return others == 0 ? std::string()
                     : formatText("; %llu other table%s judged since the last line, none kept", count(others),
                                  others == 1 ? "" : "s");
}

SuiteResult BestTableKeeper::settle(TrainingSession& session, std::optional<SuiteResult> last, LogLines& log)
{
  // The last table's whole verdict, to compare with the best's and to print.
  if (last && !last->complete())
    last = evaluateSuite(session.table(), config_, *suite_);
  if (best_ && last && better(best_->result, *last))
  {
    // The best table seen is what the run saves (and what the session holds from now on).
    log.push_back(
        {LogLine::Level::Info,
         formatText("keeping the table of episode %llu (worst case %llu balanced) over the last one (%llu)",
                    count(best_->episode), count(best_->result.worstBalanced()), count(last->worstBalanced()))});
    session.replaceTable(best_->table);
    last = best_->result;
  }
  // Not evaluated during training: the table's verdict, whole when the suite is the run's goal;
  // for information (trained until solved), each case stops once its verdict is known: a table
  // trained to solved fails most cases within their first episodes, where running all of them took
  // most of the process's time (issue 29). The rows say where a case stopped, and
  // an evaluation by the suite (Setting::SuiteEvaluation) runs every episode.
  const bool for_information = config_.limits.until != TrainUntil::SuitePasses;
  if (!last)
    last = evaluateSuite(session.table(), config_, *suite_,
                         for_information ? SuiteRun::eachCaseUntilDecided() : SuiteRun::complete());
  if (!for_information)
    log.push_back({LogLine::Level::Info,
                   formatText("robustness of the saved table (%s, greedy, %llu episodes per case):\n",
                              suite_path_.c_str(), count(suite_->episodes)) +
                       last->table(),
                   false});
  else
  {
    // Not this run's goal: what the table would be worth on a robot, with where to go for that,
    // rather than a FAILED beside the SOLVED that follows.
    const std::string verdict = (last->passed() ? std::string("every case passes: robust by this suite as well")
                                                : formatText("%zu of %zu cases pass: not yet a table for a real robot",
                                                             last->casesPassed(), last->cases_in_suite)) +
                                (last->complete() ? ""
                                                  : " (each case stopped once decided; " +
                                                        names_(Setting::SuiteEvaluation) + " runs every episode)");
    log.push_back(
        {LogLine::Level::Info,
         formatText("robustness of the saved table, for information (%s, greedy, %s%llu episodes per case):\n",
                    suite_path_.c_str(), last->complete() ? "" : "up to ", count(suite_->episodes)) +
             last->rows() + verdict +
             ". This run's goal was solved (the tutorial's), not this suite; config/robust.yaml trains until this "
             "suite passes (docs/robust_tables.md)",
         false});
  }
  return *last;
}

LogLines BestTableKeeper::restore(RunFolder& folder)
{
  LogLines log;
  const std::uint64_t recorded = folder.record().best_episode;
  if (recorded == 0 || !evaluatesDuringTraining())
    return log;
  try
  {
    QTable table = folder.loadBestTable();
    SuiteResult result = evaluateSuite(table, config_, *suite_);
    const std::uint64_t episode = table.episodes;
    best_ = BestTable{std::move(table), std::move(result), episode};
  }
  catch (const std::exception& e)  // FileError, or a ConfigError: the table does not fit this configuration
  {
    log.push_back({LogLine::Level::Warn,
                   formatText("the run's best table (episode %llu) cannot be used (%s): the best is looked for afresh",
                              count(recorded), e.what())});
    folder.bestTableLost();
    return log;
  }
  folder.bestTableKept(*best_);
  log.push_back(
      {LogLine::Level::Info,
       formatText("the best table so far is still the one to beat: episode %llu, worst case %llu balanced (%s)",
                  count(best_->episode), count(best_->result.worstBalanced()), folder.bestTablePath().c_str())});
  return log;
}

}  // namespace cartpole_qlearning
