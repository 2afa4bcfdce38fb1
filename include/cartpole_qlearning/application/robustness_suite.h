// A robustness suite: what a table is worth on a robot. Each case is a set of conditions a real
// cart-pole meets (a late command, noisy sensors, other masses, a weaker motor, pushes, wider
// starts, all at once: perturbations.h), run greedily for a number of episodes; a case passes
// when enough of them balance to the step limit. train_headless --evaluate TABLE --suite FILE,
// evaluate.launch and the end of every training run use it.
#pragma once

#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace cartpole_qlearning
{
struct SuiteCase
{
  std::string name;
  // The case's physics (the configuration's, with the case's physics keys over it) and start region.
  CartPoleParams physics;
  EngineParams engine;  // the configuration's, or the case's own (a case may name a model)
  double start_state_bound = 0.05;
  PerturbationParams perturbations;
  std::uint64_t pass = 95;  // balanced episodes (of the suite's episodes) needed to pass
};

struct RobustnessSuite
{
  std::string origin;            // the file, for messages
  std::uint64_t episodes = 100;  // per case
  std::uint64_t seed = 1000;     // the evaluation's own seed: start states, noise, draws, pushes
  // The suite's own criterion, whatever the training used: balanced means reaching this many
  // steps, from starts in +-start_state_bound (a case's physics/start_state_bound overrides it).
  unsigned max_episode_steps = 500;
  double start_state_bound = 0.05;
  std::vector<SuiteCase> cases;
};

// Reads a suite file (see config/robust_suite.yaml). base: the physics that the cases' keys
// override (the configuration the table was trained with; its step limit and start region play
// no part: the suite's own do). Throws ConfigError naming
// the case and key on a bad value or an unknown key.
RobustnessSuite parseRobustnessSuite(const std::string& yaml, const std::string& origin, const TrainingConfig& base);
RobustnessSuite loadRobustnessSuite(const std::string& path, const TrainingConfig& base);

struct CaseResult
{
  std::string name;
  std::uint64_t episodes = 0;  // the case's episodes (the suite's)
  std::uint64_t run = 0;       // of which were run: fewer when the case stopped once decided
  std::uint64_t balanced = 0;  // reached the task's step limit without falling
  std::uint64_t pass = 0;
  double mean_return = 0.0;  // over the episodes run
  // The balanced episodes the run was decided against when SuiteRun::target said other than pass
  // (0: pass).
  std::uint64_t target = 0;
  std::uint64_t steps = 0;  // steps run over the episodes run (greedy steps: the verdict's cost)
  // The episodes that fell, by their index in the case's draw (0 .. episodes - 1), in the order run.
  std::vector<std::uint32_t> fallen{};
  bool passed() const
  {
    return balanced >= pass;
  }
  std::uint64_t decidedAgainst() const
  {
    return target > 0 ? target : pass;
  }
  bool reachedTarget() const
  {
    return balanced >= decidedAgainst();
  }
  bool cutShort() const
  {
    return run < episodes;
  }
};

// Whether a case's episodes can be run in any order: each episode's start and physics are drawn
// at its reset and its steps draw nothing (no sensor noise, no pushes; the equations' engine), so
// episode e is the same whatever the table did in the episodes before it. (A noisy case's
// episode e meets the noise drawn after every step of the episodes before it: run in order only.)
bool episodesRunInAnyOrder(const SuiteCase& suite_case);

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
  // a controller that knows its robot answers late); 0: for the state observed.
  unsigned predict_delay_steps = 0;

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

struct SuiteResult
{
  std::vector<CaseResult> cases;  // in the order run; a suite stopped at a failure lists the cases run
  std::size_t cases_in_suite = 0;
  // What a return means when the reward is not CartPole-v1's +1 a step ("sutton_barto's reward, 0 a
  // step, -1 on the fall"), printed under the rows; "" for gymnasium.
  std::string reward_note;
  // Decided by SuiteRun::falls's probe: `cases` is the one case the probe found short of its target.
  bool probed = false;
  bool passed() const;
  // A case run can no longer pass, whatever its episodes not run would give. (A suite stopped
  // against targets other than pass may be neither passed() nor failed(): not decided.)
  bool failed() const;
  // The suite stopped at a failing case before running them all.
  bool stoppedEarly() const
  {
    return cases.size() < cases_in_suite;
  }
  // Every case run to its last episode: the verdict and worstBalanced() are the whole ones.
  bool complete() const;
  // Every case reached its target (with a stopped suite: false).
  bool reachedTargets() const;
  // The fewest balanced episodes of any case, and that case's name.
  std::uint64_t worstBalanced() const;
  // "nominal 100/100, one_step_late 97/100, ... : PASSED" on one line; a case cut short reads
  // "one_step_late 3/9 (stopped: failed)", a suite stopped early ends "FAILED (stopped at one_step_late)".
  std::string summary() const;
  // The number of cases run that passed.
  std::size_t casesPassed() const;
  // A header and one line per case, aligned: for a console.
  std::string rows() const;
  // rows(), then the verdict (summary()).
  std::string table() const;
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

// A mean return as printed with this many decimals: rounded there, a zero without its sign.
// Under sutton_barto a case where 2 of 100 fell has a mean of -0.02, which "%.1f" prints as
// "-0.0"; printed through this it reads 0.0, and the balanced column says who fell.
double shownReturn(double value, int decimals);

}  // namespace cartpole_qlearning
