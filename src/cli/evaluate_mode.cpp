#include "headless_run.h"

#include "cartpole_qlearning/application/robustness_suite.h"

#include <cstdio>

namespace cartpole_qlearning
{
// --evaluate TABLE: the table run greedily, learning nothing and writing nothing, ending with
// "evaluated=N balanced=M mean_return=R" (the application's verdict). Exit 2 when the table cannot
// be used.
int evaluateMode(const HeadlessOptions& options, const HeadlessSetup& setup)
{
  HeadlessRun run(options, setup, options.seed.value_or(0));
  if (const std::optional<int> status = run.start())
    return *status;
  run.run();
  const EvaluationVerdict verdict = run.application().verdict();
  std::printf("evaluated=%llu balanced=%llu mean_return=%.3f\n", static_cast<unsigned long long>(verdict.episodes),
              static_cast<unsigned long long>(verdict.balanced), shownReturn(verdict.mean_return, 3));
  return run.exitStatus();
}

}  // namespace cartpole_qlearning
