// How a robustness suite runs: each case's greedy episodes (greedy_episodes.h) on a simulation of
// its own, cases side by side on the cores this process may use, stopped once decided when asked,
// with a probe of remembered falls during training.
#pragma once

#include "cartpole_qlearning/application/suite_file.h"
#include "cartpole_qlearning/application/suite_report.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace cartpole_qlearning
{
// What training remembers between evaluations, by suite case index: the episodes each case last
// saw fall. A table that fell on an episode is likely to fall there again after one more training
// episode; a case whose episodes run in any order (episodesRunInAnyOrder) tries those first
// (SuiteRun::falls).
struct FallenEpisodes
{
  // Evaluations a case is not probed for after a probe whose first episode balanced.
  static constexpr unsigned kRest = 8;
  struct Case
  {
    std::vector<std::uint32_t> fallen{};
    unsigned rest = 0;
  };
  std::vector<Case> by_case;
};

// Where each case of an evaluation stopped, by suite case index: the simulation ready for its next
// episode (its draws where the episodes run left them), and the counts so far. An evaluation of the
// same table that asks more of a case goes on from there instead of running its first episodes
// again (SuiteRun::progress).
struct SuiteProgress
{
  struct Case
  {
    std::unique_ptr<CartPoleSimulation> simulation;  // null: the case starts from its first episode
    CaseResult result;
    double returns = 0.0;  // summed in the order run, as a case run whole sums them
  };
  std::vector<Case> by_case;
};

// How a suite is run. The verdict (passed or not) is the same whatever these say: the episodes of
// a case are drawn from its own stream, in order, so stopping early only leaves out episodes that
// could not change it, and a case's result does not depend on which thread ran it.
struct SuiteRun
{
  // A case stops at its deciding episode: its (episodes - target + 1)-th fall, or its target-th
  // balanced episode.
  bool stop_cases_when_decided = false;
  // The suite stops at its first case below its target, in `order`; the cases after it are not run.
  bool stop_at_first_failure = false;
  // The balanced episodes each case is decided against; empty: the case's pass. (Training asks
  // whether a table can beat the best so far, which may take more or fewer than pass.)
  std::function<std::uint64_t(const SuiteCase&)> target;
  // The cases' indices in the order to run them (each once); empty: as the suite lists them.
  std::vector<std::size_t> order;
  // With stop_at_first_failure, a probe before the cases run in `order`: of the cases whose
  // episodes run in any order, the one failed by the fewest falls (unless it rests after a probe
  // whose first episode balanced) tries its remembered falls and then its other episodes in
  // order. When it falls as often as keeps it from its target the suite has not reached its
  // targets (its result is that case, cut short); at the first episode that balances the cases
  // run in `order` as without it. passed()
  // and reachedTargets() are those without: the falls are the case's own episodes, and nothing
  // else about the run changes. (Which cases are listed, and with targets other than the pass
  // marks whether failed() can say so yet, may differ: a probe can stop at a case that is short of
  // its target but not of its pass mark.) evaluateSuite leaves this evaluation's falls in it;
  // null: no probe.
  FallenEpisodes* falls = nullptr;
  // Where the cases of an earlier evaluation of the same table stopped, and where each case run in
  // order stops now. A complete run (stop_cases_when_decided false) goes on from there: its
  // episodes and draws are those it would meet from the start, and every episode runs, so the
  // result is the same. (A run that stops when decided starts afresh: the earlier run may have
  // gone past where it would stop.) Training judges whole a table whose cut-short evaluation
  // reached its targets: the episodes that one ran are not run twice. The caller keeps it to one
  // table, configuration and suite. Null: every case from its first episode.
  SuiteProgress* progress = nullptr;
  // Cases run side by side on this many threads (0: one per core this process may use).
  unsigned threads = 0;
  // Each decision for the state the table's model predicts this many steps ahead (DelayPredictor:
  // a controller that knows its robot answers late); 0: for the state observed. By default the
  // delay is found in each episode from its states, as the controller finds it when not told: a
  // table is judged as it will run.
  unsigned predict_delay_steps = kDelayFoundFromStates;

  // The complete verdict: every case to its last episode.
  static SuiteRun complete()
  {
    return SuiteRun();
  }
  // Every case, each until its own verdict is known (its pass-th balanced episode or its
  // (episodes - pass + 1)-th fall): the verdict of every case, for a fraction of the episodes when
  // the table is far from passing (the for-information verdict at the end of a run trained until
  // solved).
  static SuiteRun eachCaseUntilDecided()
  {
    SuiteRun run;
    run.stop_cases_when_decided = true;
    return run;
  }
  // During training: only whether the table passes, as soon as that is known.
  static SuiteRun untilDecided(std::vector<std::size_t> order)
  {
    SuiteRun run;
    run.stop_cases_when_decided = true;
    run.stop_at_first_failure = true;
    run.order = std::move(order);
    return run;
  }
};

// Runs the table greedily (no learning, no exploration) on one case. config: the task (step
// limit, thresholds, reward) and the agent's features and actions the table was made for;
// evaluateSuite runs each case with the suite's step limit in place of the task's.
// Throws ConfigError when the table does not fit the configuration.
// stop_when_decided: stop once the case has `target` balanced episodes or can no longer reach
// it (0: the case's pass). predict_delay_steps: as SuiteRun's (the model: config's physics).
// progress: as SuiteRun's, for this case (null: from the first episode, nothing kept).
CaseResult evaluateCase(const QTable& table, const TrainingConfig& config, const SuiteCase& suite_case,
                        std::uint64_t episodes, std::uint64_t seed, bool stop_when_decided = false,
                        std::uint64_t target = 0, unsigned predict_delay_steps = 0,
                        SuiteProgress::Case* progress = nullptr);
SuiteResult evaluateSuite(const QTable& table, const TrainingConfig& config, const RobustnessSuite& suite,
                          const SuiteRun& how = SuiteRun::complete());

// Runs the given episodes of a case (by index in its draw; the case's episodes must run in any
// order: episodesRunInAnyOrder) in that order, stopping at the first that balances or once
// `falls_to_stop` have fallen. The result counts the episodes run (run, balanced, fallen, steps,
// mean_return) out of `episodes`, the case's episodes.
CaseResult evaluateEpisodes(const QTable& table, const TrainingConfig& config, const SuiteCase& suite_case,
                            std::uint64_t episodes, std::uint64_t seed, const std::vector<std::uint32_t>& which,
                            std::uint64_t falls_to_stop, std::uint64_t target = 0, unsigned predict_delay_steps = 0);

// The order for the next evaluation during training: the case that fell short of its target last
// comes first (the likeliest to again), the others keep their order (a result decided by the
// probe leaves it as it is). order: the indices of the suite's cases.
void failedCaseFirst(std::vector<std::size_t>& order, const SuiteResult& result, const RobustnessSuite& suite);
}  // namespace cartpole_qlearning
