// The robustness suite during training (training/suite, run every training/suite_every episodes
// on a copy of the table) and the best table it has seen: a table that passes beats one that does
// not, then the one more balanced in its worst case, the first of equals. Training ends on the
// best table seen rather than the last, a checkpoint saves the best beside the run's table, and a
// resumed run goes on comparing against it. Under training/until suite_passes, the suite passing
// ends training.
#pragma once

#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/common/setting_names.h"
#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/application/run_folder.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
class BestTableKeeper
{
public:
  // config: training/suite, suite_every, best_every, until and progress_every (the cadence of the
  // lines for tables not kept); the physics the suite's cases vary.
  // learning: false (evaluating) keeps no suite, unless control (a table about to drive a robot:
  // judgeBeforeControl). suite_folders: where a relative suite is looked for, in order. names:
  // how the front end names its settings (the command a complete evaluation takes).
  BestTableKeeper(const TrainingConfig& config, bool learning, std::vector<std::string> suite_folders,
                  bool control = false, SettingNames names = {});

  // Finds and reads the suite (training, unless training/suite is none). Throws ConfigError when
  // training evaluates it (suite_every > 0); else says that the run ends without a verdict.
  LogLines loadSuite();
  bool hasSuite() const
  {
    return suite_ != nullptr;
  }

  // The suite's verdict on the session's table when it is due at the session's last episode (at
  // suite_every's cadence, and when training ends), said; the table is kept when it is the best
  // so far. Nothing when not due. Once there is a best, the verdict of a table that cannot beat it
  // (or, between training/best_every's evaluations, that does not pass) is cut short
  // (SuiteResult::complete() false) and said at most once in each stretch of
  // training/progress_every episodes (progress_every 0: only when training ends), the next line
  // saying how many such tables there were since the last one; against a failing best such a table fails, and
  // its passed() is false as its whole verdict's would be. (Against a passing best, a cut-short
  // verdict says nothing of passing: under training/until suite_passes the keeper then judges
  // every table whole, since passing ends training.)
  std::optional<SuiteResult> evaluateWhenDue(const TrainingSession& session, bool training_ends, LogLines& log);
  // Training ends (needs the suite): the table it saves is the best seen when that beats the last
  // (the session then holds it), said. Returns the verdict of that table (`last`, the best's, or
  // evaluated now when the suite has not run at this episode), said as a table.
  SuiteResult settle(TrainingSession& session, std::optional<SuiteResult> last, LogLines& log);

  // A table about to drive a robot (mode control): the suite's verdict on it, decided case by case
  // and stopped at the first failure, said once and plainly (a warning when it fails: the table
  // was not shown to hold a robot that is not its model). Decisions for the state predicted
  // predict_delay_steps ahead, as the controller will make them. Nothing without a suite.
  LogLines judgeBeforeControl(const QTable& table, unsigned predict_delay_steps) const;

  // A resumed run goes on comparing against the best table its folder holds, evaluated again (the
  // same suite gives the same verdict; a suite changed since is applied to both tables alike).
  // One that cannot be read or does not fit is said and forgotten.
  LogLines restore(RunFolder& folder);

  // The best table seen so far (when the suite runs during training), else null.
  const BestTable* best() const
  {
    return best_ ? &*best_ : nullptr;
  }

private:
  bool evaluatesDuringTraining() const
  {
    return learning_ && suite_ && config_.limits.suite_every > 0;
  }

  TrainingConfig config_;
  bool learning_;
  bool control_;
  std::vector<std::string> suite_folders_;
  SettingNames names_;
  std::unique_ptr<RobustnessSuite> suite_;  // none: no verdict (training/suite none, or not found)
  std::string suite_path_;
  std::optional<BestTable> best_;
  // The order the next evaluation runs the cases in: the last to fall short first.
  std::vector<std::size_t> order_;
  // The episodes each case last saw fall, tried first by the next evaluation (SuiteRun::falls).
  FallenEpisodes falls_;
  // "; N other tables judged since the last line, none kept" for the next line said ("" when
  // none), and the count starts again.
  std::string othersNotKept();

  // Tables not kept (no better than the best, or not passing) and not said since the last line
  // (at most one such line in each stretch of progress_every episodes).
  std::uint64_t not_kept_unsaid_ = 0;
  // episode / progress_every at the last line of a table not kept.
  std::uint64_t progress_said_ = 0;
};

}  // namespace cartpole_qlearning
