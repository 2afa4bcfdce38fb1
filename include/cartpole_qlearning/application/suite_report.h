// What a robustness suite said of a table: each case's counts, the verdict, and the lines
// train_headless, evaluate.launch and a training run's end print.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
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

// A mean return as printed with this many decimals: rounded there, a zero without its sign.
// Under sutton_barto a case where 2 of 100 fell has a mean of -0.02, which "%.1f" prints as
// "-0.0"; printed through this it reads 0.0, and the balanced column says who fell.
double shownReturn(double value, int decimals);

}  // namespace cartpole_qlearning
