#include "headless_modes.h"

#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/learning/table_config.h"

#include <cstdio>
#include <iostream>

namespace cartpole_qlearning
{
// --evaluate TABLE --suite FILE: every case of the suite, greedily; exit 0 when it ran (the verdict
// is in the last line), 2 on a bad suite, table or configuration.
int suiteMode(const HeadlessOptions& options, const HeadlessSetup& setup)
{
  const std::string& suite_path = options.suite_path;
  const std::string& table_path = options.evaluate_path;
  RobustnessSuite suite;
  try
  {
    suite = loadRobustnessSuite(suite_path, setup.config);
  }
  catch (const ConfigError& e)
  {
    std::cerr << "train_headless: --suite: " << e.what() << "\n";
    return 2;
  }
  if (options.seed)
    suite.seed = *options.seed;
  SuiteResult result;
  try
  {
    const QTable table = loadTable(setup.table_dir, table_path);
    const std::string contradiction =
        tableContradiction(setup.config, setup.config_origin, table, tablePath(setup.table_dir, table_path));
    if (!contradiction.empty())
      throw FileError(contradiction);
    SuiteRun how = SuiteRun::complete();
    how.predict_delay_steps =
        options.predict_delay_given ? static_cast<unsigned>(options.predict_delay) : kDelayFoundFromStates;
    result = evaluateSuite(table, setup.config, suite, how);
  }
  catch (const std::runtime_error& e)  // FileError, ConfigError: the table cannot be read or does not fit
  {
    std::cerr << "train_headless: --evaluate " << table_path << ": " << e.what() << "\n";
    return 2;
  }
  const std::string predicting =
      options.predict_delay_given && options.predict_delay == 0 ? ""
      : !options.predict_delay_given || options.predict_delay == kDelayFoundFromStates
          ? ", each case's delay found from its states and each decision for the state predicted that far ahead"
          : ", each decision for the state predicted " + std::to_string(options.predict_delay) +
                (options.predict_delay == 1 ? " step" : " steps") + " ahead";
  if (!options.quiet)
    std::printf("suite %s: %zu cases, %llu greedy episodes each, seed %llu%s\n%s\n", suite_path.c_str(),
                suite.cases.size(), static_cast<unsigned long long>(suite.episodes),
                static_cast<unsigned long long>(suite.seed), predicting.c_str(), result.table().c_str());
  std::size_t passed = 0;
  for (const CaseResult& c : result.cases)
    passed += c.passed();
  std::printf("suite=%s cases=%zu passed=%zu worst=%llu/%llu\n", result.passed() ? "PASSED" : "FAILED",
              result.cases.size(), passed, static_cast<unsigned long long>(result.worstBalanced()),
              static_cast<unsigned long long>(suite.episodes));
  return 0;
}

}  // namespace cartpole_qlearning
