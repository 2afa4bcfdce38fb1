#include "cartpole_qlearning/application/robustness_suite.h"

#include "cartpole_qlearning/simulation/engine_registry.h"
#include "cartpole_qlearning/simulation/physics_engines.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/learning/q_learning_agent.h"

#include <yaml-cpp/yaml.h>

#ifdef __linux__
#include <sched.h>
#endif

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
// The cores this process may run on: under taskset or a container's cpuset fewer than the
// machine has (std::thread::hardware_concurrency counts the machine's), and a second thread on
// one core only takes turns with the first.
unsigned usableCores()
{
#ifdef __linux__
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0)
    return static_cast<unsigned>(std::max(1, CPU_COUNT(&allowed)));
#endif
  return std::max(1u, std::thread::hardware_concurrency());
}

std::uint64_t wholeNumber(const YAML::Node& node, const std::string& where, std::uint64_t min, std::uint64_t max)
{
  long long value = 0;
  try
  {
    value = node.as<long long>();
  }
  catch (const YAML::Exception&)
  {
    throw ConfigError(where + " = '" + YAML::Dump(node) + "' is not allowed (must be a whole number)");
  }
  if (value < static_cast<long long>(min) || static_cast<unsigned long long>(value) > max)
    throw ConfigError(where + " = " + std::to_string(value) + " is not allowed (must be in [" + std::to_string(min) +
                      ", " + std::to_string(max) + "])");
  return static_cast<std::uint64_t>(value);
}

double boundValue(const YAML::Node& node, const std::string& where)
{
  double value = -1.0;
  try
  {
    value = node.as<double>();
  }
  catch (const YAML::Exception&)
  {
  }
  if (!(std::isfinite(value) && value >= 0.0))
    throw ConfigError(where + " = '" + YAML::Dump(node) + "' is not allowed (must be a finite number >= 0)");
  return value;
}
}  // namespace

RobustnessSuite parseRobustnessSuite(const std::string& yaml, const std::string& origin, const TrainingConfig& base)
{
  RobustnessSuite suite;
  suite.origin = origin;
  YAML::Node root;
  try
  {
    root = YAML::Load(yaml);
  }
  catch (const YAML::Exception& e)
  {
    throw ConfigError(origin + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap())
    throw ConfigError(origin + ": must be a map with the keys episodes, seed and cases");
  for (const auto& entry : root)
  {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : YAML::Dump(entry.first);
    if (key == "episodes")
      suite.episodes = wholeNumber(entry.second, origin + ": episodes", 1, 1000000);
    else if (key == "seed")
      suite.seed = wholeNumber(entry.second, origin + ": seed", 0, std::numeric_limits<long long>::max());
    else if (key == "max_episode_steps")
      suite.max_episode_steps = static_cast<unsigned>(
          wholeNumber(entry.second, origin + ": max_episode_steps", 1, std::numeric_limits<int>::max()));
    else if (key == "start_state_bound")
      suite.start_state_bound = boundValue(entry.second, origin + ": start_state_bound");
    else if (key != "cases")
      throw ConfigError(origin + ": unknown key " + key +
                        " (known keys: episodes, seed, max_episode_steps, start_state_bound, cases)");
  }
  const YAML::Node cases = root["cases"];
  if (!cases || !cases.IsSequence() || cases.size() == 0)
    throw ConfigError(origin + ": cases must be a list of cases, each with a name");
  std::set<std::string> names;
  for (std::size_t i = 0; i < cases.size(); ++i)
  {
    const YAML::Node node = cases[i];
    const std::string where = origin + ": cases[" + std::to_string(i) + "]";
    if (!node.IsMap() || !node["name"] || !node["name"].IsScalar() || node["name"].Scalar().empty())
      throw ConfigError(where + " must be a map with a name");
    SuiteCase c;
    c.name = node["name"].Scalar();
    if (!names.insert(c.name).second)
      throw ConfigError(where + ": the name " + c.name + " is used twice");
    c.physics = base.physics;
    c.engine = base.engine;
    c.start_state_bound = suite.start_state_bound;
    YAML::Node sections(YAML::NodeType::Map);
    for (const auto& entry : node)
    {
      const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : YAML::Dump(entry.first);
      if (key == "pass")
        c.pass = wholeNumber(entry.second, origin + ": case " + c.name + ": pass", 0, suite.episodes);
      else if (key == "physics" || key == "perturbations")
        sections[key] = entry.second;
      else if (key != "name")
        throw ConfigError(origin + ": case " + c.name + ": unknown key " + key +
                          " (known keys: name, pass, physics, perturbations)");
    }
    // The case's sections, read by the configuration's own readers: the same keys, checks and messages.
    // (A case's model is relative to the suite file's folder.)
    const auto source = parseYamlParameters(YAML::Dump(sections), origin + ": case " + c.name, configFolder(origin));
    readPhysics(*source, c.physics, c.start_state_bound, c.engine);
    c.perturbations = readPerturbations(*source);
    checkPerturbationsFitEngine(*source, c.engine, c.perturbations);
    suite.cases.push_back(c);
  }
  return suite;
}

RobustnessSuite loadRobustnessSuite(const std::string& path, const TrainingConfig& base)
{
  std::ifstream in(path);
  if (!in)
    throw ConfigError(path + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return parseRobustnessSuite(text.str(), path, base);
}

namespace
{
// The greedy loop every verdict runs: the steps a TrainingSession that does not learn takes (the
// same rows, the same first-best action, the same task, returns summed in the same order), without
// its bookkeeping (the learning branch, the solved window, episode summaries) or an agent that
// holds a copy of the table.
class GreedyEpisodes
{
public:
  // Throws ConfigError when the table does not fit the configuration.
  GreedyEpisodes(const QTable& table, const TrainingConfig& config, unsigned predict_delay_steps)
    : table_(checkedTable(table, config)),
      task_(config.task),
      features_(config.agent.featureParams(), config.agent.actions.size()),
      efforts_(table.actions()),
      predictor_(config.physics, predict_delay_steps),
      predicting_(predict_delay_steps > 0)
  {
  }

  // One episode from the simulation's next random reset, counted into result (its return into
  // returns); `index`: the episode's place in the case's draw.
  void run(CartPoleSimulation& simulation, std::uint32_t index, CaseResult& result, double& returns)
  {
    simulation.resetRandom();
    // The model the table learnt, for a prediction of the robot's delay (none: decide for what is seen).
    predictor_.begin();
    features_.activeRows(predicting_ ? predictor_.predict(simulation.observation()) : simulation.observation(), rows_);
    std::size_t action = QLearningAgent::greedyAction(table_, rows_);
    unsigned steps = 0;
    double episode_return = 0.0;
    StepOutcome outcome;
    for (;;)
    {
      predictor_.sent(efforts_[action]);
      simulation.step(efforts_[action]);
      outcome = task_.evaluate(simulation.observation(), ++steps);
      episode_return += outcome.score;  // the return the solved window counts (TaskParams::scoreReward())
      if (outcome.done())
        break;
      // The action just taken is part of what a previous_action table sees of the state.
      features_.activeRows(predicting_ ? predictor_.predict(simulation.observation()) : simulation.observation(), rows_,
                           action + 1);
      action = QLearningAgent::greedyAction(table_, rows_);
    }
    result.steps += steps;
    const bool balanced = outcome.truncated && !outcome.terminated;
    result.balanced += balanced;
    if (!balanced)
      result.fallen.push_back(index);
    returns += episode_return;
    ++result.run;
  }

private:
  static const QTable& checkedTable(const QTable& table, const TrainingConfig& config)
  {
    const std::string invalid = config.agent.validate();
    if (!invalid.empty())
      throw std::invalid_argument(invalid);
    const std::string mismatch = tableShapeMismatch(config.agent.featureParams(), config.agent.actions, table);
    if (!mismatch.empty())
      throw ConfigError("the table does not fit the configuration: " + mismatch);
    return table;
  }

  const QTable& table_;
  const CartPoleTask task_;
  const FeatureMap features_;
  const std::vector<double>& efforts_;
  DelayPredictor predictor_;
  const bool predicting_;
  ActiveRows rows_;
};

CaseResult startResult(const SuiteCase& suite_case, std::uint64_t episodes, std::uint64_t target)
{
  CaseResult result;
  result.name = suite_case.name;
  result.pass = suite_case.pass;
  result.episodes = episodes;
  result.target = target;
  return result;
}

// The falls after which a case can no longer reach its target.
std::uint64_t fallsToFail(const CaseResult& result)
{
  const std::uint64_t decided_at = result.decidedAgainst();
  return result.episodes >= decided_at ? result.episodes - decided_at + 1 : 0;
}
}  // namespace

bool episodesRunInAnyOrder(const SuiteCase& suite_case)
{
  return engineOf(suite_case.engine).episodes_independent && !suite_case.perturbations.drawsWhileStepping();
}

namespace
{
// evaluateCase, abandoned between episodes once `abandoned` says its result will not be used.
CaseResult runCase(const QTable& table, const TrainingConfig& config, const SuiteCase& suite_case,
                   std::uint64_t episodes, std::uint64_t seed, bool stop_when_decided, std::uint64_t target,
                   unsigned predict_delay_steps, SuiteProgress::Case* progress, const std::function<bool()>& abandoned)
{
  GreedyEpisodes greedy(table, config, predict_delay_steps);
  std::unique_ptr<CartPoleSimulation> simulation;
  CaseResult result = startResult(suite_case, episodes, target);
  double returns = 0.0;
  if (progress != nullptr && !stop_when_decided && progress->simulation && progress->result.episodes == episodes &&
      progress->result.name == suite_case.name)
  {
    // Going on where an evaluation of this table stopped: its counts, with this run's target.
    simulation = std::move(progress->simulation);
    result = std::move(progress->result);
    result.target = target;
    result.pass = suite_case.pass;
    returns = progress->returns;
  }
  else
    simulation = std::make_unique<CartPoleSimulation>(makeSimulation(
        suite_case.physics, suite_case.engine, suite_case.start_state_bound, seed, suite_case.perturbations));
  // Decided once target episodes balanced, or once more fell than that allows.
  const std::uint64_t decided_at = result.decidedAgainst();
  const std::uint64_t falls_to_fail = fallsToFail(result);
  const auto decided = [&]() {
    return stop_when_decided && (result.balanced >= decided_at || result.run - result.balanced >= falls_to_fail);
  };
  // Decided is asked after each episode run here (a case started afresh runs at least one); an
  // abandoned case stops before its next.
  for (std::uint64_t e = result.run; e < episodes && !(e > 0 && decided()) && !(abandoned && abandoned()); ++e)
    greedy.run(*simulation, static_cast<std::uint32_t>(e), result, returns);
  result.mean_return = result.run > 0 ? returns / static_cast<double>(result.run) : 0.0;
  if (progress != nullptr)
  {
    progress->simulation = std::move(simulation);
    progress->result = result;
    progress->returns = returns;
  }
  return result;
}
}  // namespace

CaseResult evaluateCase(const QTable& table, const TrainingConfig& config, const SuiteCase& suite_case,
                        std::uint64_t episodes, std::uint64_t seed, bool stop_when_decided, std::uint64_t target,
                        unsigned predict_delay_steps, SuiteProgress::Case* progress)
{
  return runCase(table, config, suite_case, episodes, seed, stop_when_decided, target, predict_delay_steps, progress,
                 {});
}

CaseResult evaluateEpisodes(const QTable& table, const TrainingConfig& config, const SuiteCase& suite_case,
                            std::uint64_t episodes, std::uint64_t seed, const std::vector<std::uint32_t>& which,
                            std::uint64_t falls_to_stop, std::uint64_t target, unsigned predict_delay_steps)
{
  if (!episodesRunInAnyOrder(suite_case))
    throw std::invalid_argument("evaluateEpisodes: the episodes of case " + suite_case.name +
                                " draw while they run (noise or pushes) or run on a model: only in order");
  GreedyEpisodes greedy(table, config, predict_delay_steps);
  CaseResult result = startResult(suite_case, episodes, target);
  double returns = 0.0;
  for (const std::uint32_t e : which)
  {
    if (e >= episodes)
      throw std::invalid_argument("evaluateEpisodes: episode " + std::to_string(e) + " of case " + suite_case.name +
                                  ", which has " + std::to_string(episodes));
    // Episode e's draws: the resets of the episodes before it draw the same whatever was run
    // between them (their steps draw nothing).
    CartPoleSimulation simulation = makeSimulation(suite_case.physics, suite_case.engine, suite_case.start_state_bound,
                                                   seed, suite_case.perturbations);
    for (std::uint32_t before = 0; before < e; ++before)
      simulation.resetRandom();
    const std::uint64_t balanced = result.balanced;
    greedy.run(simulation, e, result, returns);
    if (result.balanced > balanced || result.fallen.size() >= falls_to_stop)
      break;
  }
  result.mean_return = result.run > 0 ? returns / static_cast<double>(result.run) : 0.0;
  return result;
}

SuiteResult evaluateSuite(const QTable& table, const TrainingConfig& config, const RobustnessSuite& suite,
                          const SuiteRun& how)
{
  TrainingConfig judged = config;
  judged.task.max_episode_steps = suite.max_episode_steps;
  std::vector<std::size_t> order = how.order;
  if (order.empty())
    for (std::size_t i = 0; i < suite.cases.size(); ++i)
      order.push_back(i);
  if (order.size() != suite.cases.size() || std::set<std::size_t>(order.begin(), order.end()).size() != order.size() ||
      *std::max_element(order.begin(), order.end()) >= suite.cases.size())
    throw std::invalid_argument("evaluateSuite: the order must name each of the suite's cases once");

  SuiteResult result;
  result.cases_in_suite = suite.cases.size();
  const RewardScheme score = config.task.scoreReward();
  if (score != RewardScheme::Gymnasium)
    result.reward_note = toString(score) + "'s reward, " + rewardMeaning(score);
  const auto targetOf = [&how](const SuiteCase& c) { return how.target ? how.target(c) : c.pass; };

  // The probe (SuiteRun::falls): a table that fell on an episode after the last training episode
  // mostly falls there again after this one, and a case that needs every episode (nominal) is
  // failed by one fall, where the case that failed last (first in `order`) may need several
  // long episodes to fall as often as fails it (all_at_once: 6 of 100, each balanced episode
  // before them 3000 steps). Seed 0's robust.yaml run: 350 of 389 tables sampled that failed
  // the suite failed nominal too; 1,646 of its evaluations were then decided by the probe at
  // about 400 greedy steps each, where all_at_once took 33,000 (docs/benchmarks.md).
  FallenEpisodes* const falls = how.stop_at_first_failure ? how.falls : nullptr;
  if (falls != nullptr)
  {
    falls->by_case.resize(suite.cases.size());
    // The case failed by the fewest falls (the first in `order` of those), unless it rests.
    std::uint64_t needed = 0;
    std::size_t index = suite.cases.size();
    for (const std::size_t i : order)
    {
      const SuiteCase& c = suite.cases[i];
      FallenEpisodes::Case& memory = falls->by_case[i];
      const std::uint64_t falls_to_fail = fallsToFail(startResult(c, suite.episodes, targetOf(c)));
      if (falls_to_fail == 0 || !episodesRunInAnyOrder(c))
        continue;
      if (memory.rest > 0)
        --memory.rest;
      else if (index == suite.cases.size() || falls_to_fail < needed)
      {
        needed = falls_to_fail;
        index = i;
      }
    }
    if (index < suite.cases.size())
    {
      const SuiteCase& c = suite.cases[index];
      FallenEpisodes::Case& memory = falls->by_case[index];
      // Its remembered falls, then its other episodes in order, until one balances.
      std::vector<std::uint32_t> which;
      std::vector<bool> listed(suite.episodes, false);
      for (const std::uint32_t e : memory.fallen)
        if (e < suite.episodes && !listed[e])
        {
          listed[e] = true;
          which.push_back(e);
        }
      for (std::uint32_t e = 0; e < suite.episodes; ++e)
        if (!listed[e])
          which.push_back(e);
      CaseResult probed = evaluateEpisodes(table, judged, c, suite.episodes, suite.seed, which, needed, targetOf(c),
                                           how.predict_delay_steps);
      memory.fallen = probed.fallen;
      if (probed.fallen.size() >= needed)
      {
        result.cases.push_back(std::move(probed));
        result.probed = true;
        return result;
      }
      // It balanced one: the cases run in order. A case whose first episode tried balanced rests a
      // while (a table that passes it would pay a balanced episode for nothing at every evaluation).
      if (probed.fallen.empty())
        memory.rest = FallenEpisodes::kRest;
    }
  }

  if (how.progress != nullptr)
    how.progress->by_case.resize(suite.cases.size());

  // Positions are taken in order, so when the case at position p fails every position before p
  // has been taken and runs to its end: the cases kept (up to the first failure) are the same
  // whatever the number of threads. A complete verdict keeps every case, so it takes the costliest
  // first (the threads then end together, not one of them alone on a noisy case); each result
  // still goes to its own position.
  std::vector<std::size_t> taken(order.size());
  for (std::size_t p = 0; p < taken.size(); ++p)
    taken[p] = p;
  if (!how.stop_at_first_failure)
    std::stable_sort(taken.begin(), taken.end(), [&](std::size_t a, std::size_t b) {
      return suite.cases[order[a]].perturbations.stepCost() > suite.cases[order[b]].perturbations.stepCost();
    });
  std::vector<CaseResult> results(order.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> first_failure{order.size()};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&]() {
    for (std::size_t t = next++; t < taken.size(); t = next++)
    {
      const std::size_t p = taken[t];
      if (how.stop_at_first_failure && p > first_failure.load())
        return;
      try
      {
        const SuiteCase& c = suite.cases[order[p]];
        // A case after one that has failed is not part of the result: it stops at its next episode
        // (run to its end, it kept the suite's answer waiting: a case that passes runs 3000-step
        // episodes for a hundred of them).
        const auto abandoned = [&first_failure, p]() { return p > first_failure.load(); };
        results[p] =
            runCase(table, judged, c, suite.episodes, suite.seed, how.stop_cases_when_decided, targetOf(c),
                    how.predict_delay_steps, how.progress != nullptr ? &how.progress->by_case[order[p]] : nullptr,
                    how.stop_at_first_failure ? std::function<bool()>(abandoned) : std::function<bool()>());
      }
      catch (...)
      {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error)
          error = std::current_exception();
        first_failure = 0;
        return;
      }
      if (!results[p].reachedTarget())
      {
        std::size_t seen = first_failure.load();
        while (p < seen && !first_failure.compare_exchange_weak(seen, p))
        {
        }
      }
    }
  };
  const unsigned cores = usableCores();
  std::size_t threads = std::min<std::size_t>(how.threads > 0 ? how.threads : cores, order.size());
  // Cases on an engine that cannot be made on several threads at once (MuJoCo's XML loading) run one
  // after another.
  if (std::any_of(suite.cases.begin(), suite.cases.end(),
                  [](const SuiteCase& c) { return !engineOf(c.engine).makes_in_parallel; }))
    threads = 1;
  std::vector<std::thread> helpers;
  for (std::size_t t = 1; t < threads; ++t)
    helpers.emplace_back(work);
  work();
  for (std::thread& helper : helpers)
    helper.join();
  if (error)
    std::rethrow_exception(error);

  const std::size_t kept = how.stop_at_first_failure ? std::min(first_failure.load() + 1, order.size()) : order.size();
  for (std::size_t p = 0; p < kept; ++p)
  {
    // What the next probe tries: the falls of each case run (none when it did not fall).
    if (falls != nullptr && episodesRunInAnyOrder(suite.cases[order[p]]))
      falls->by_case[order[p]].fallen = results[p].fallen;
    result.cases.push_back(std::move(results[p]));
  }
  return result;
}

void failedCaseFirst(std::vector<std::size_t>& order, const SuiteResult& result, const RobustnessSuite& suite)
{
  // A probe's case is left where it is: the probe tries it again next time (its falls are
  // remembered), and moved to the front it would run in order, whole, once they balance.
  if (result.probed)
    return;
  for (const CaseResult& c : result.cases)
  {
    if (c.reachedTarget())
      continue;
    for (std::size_t p = 0; p < order.size(); ++p)
    {
      if (order[p] < suite.cases.size() && suite.cases[order[p]].name == c.name)
      {
        std::rotate(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(p),
                    order.begin() + static_cast<std::ptrdiff_t>(p) + 1);
        return;
      }
    }
  }
}

double shownReturn(double value, int decimals)
{
  const double scale = std::pow(10.0, decimals);
  // + 0.0 turns -0.0 into 0.0 (IEEE 754 rounding to nearest).
  return std::round(value * scale) / scale + 0.0;
}

bool SuiteResult::passed() const
{
  return !stoppedEarly() && std::all_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.passed(); });
}

bool SuiteResult::failed() const
{
  return std::any_of(cases.begin(), cases.end(),
                     [](const CaseResult& c) { return c.balanced + (c.episodes - c.run) < c.pass; });
}

bool SuiteResult::complete() const
{
  return !stoppedEarly() && std::none_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.cutShort(); });
}

bool SuiteResult::reachedTargets() const
{
  return !stoppedEarly() &&
         std::all_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.reachedTarget(); });
}

std::uint64_t SuiteResult::worstBalanced() const
{
  std::uint64_t worst = std::numeric_limits<std::uint64_t>::max();
  for (const CaseResult& c : cases)
    worst = std::min(worst, c.balanced);
  return cases.empty() ? 0 : worst;
}

std::string SuiteResult::summary() const
{
  std::string text;
  for (const CaseResult& c : cases)
  {
    text += (text.empty() ? "" : ", ") + c.name + " " + std::to_string(c.balanced) + "/" + std::to_string(c.run);
    if (c.cutShort())
      text += " (stopped at " + std::to_string(c.run) + " of " + std::to_string(c.episodes) + ": " +
              (c.decidedAgainst() == c.pass
                   ? (c.passed() ? "passes" : "fails")
                   : (c.reachedTarget() ? "reached " : "cannot reach ") + std::to_string(c.decidedAgainst())) +
              ")";
  }
  text += std::string(": ") + (passed() ? "PASSED" : failed() ? "FAILED" : "not decided");
  if (stoppedEarly())
    text += " (stopped at " + (cases.empty() ? std::string("the start") : cases.back().name) + ", " +
            std::to_string(cases_in_suite - cases.size()) + " of " + std::to_string(cases_in_suite) + " cases not run)";
  return text;
}

std::size_t SuiteResult::casesPassed() const
{
  return static_cast<std::size_t>(
      std::count_if(cases.begin(), cases.end(), [](const CaseResult& c) { return c.passed(); }));
}

std::string SuiteResult::table() const
{
  return rows() + summary();
}

std::string SuiteResult::rows() const
{
  std::size_t width = 4;
  for (const CaseResult& c : cases)
    width = std::max(width, c.name.size());
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-*s  %8s  %6s  %11s  %s\n", static_cast<int>(width), "case", "balanced", "needed",
                "mean return", "verdict");
  out << line;
  for (const CaseResult& c : cases)
  {
    const std::string balanced = std::to_string(c.balanced) + "/" + std::to_string(c.run);
    // A case cut short says after how many of its episodes its verdict was known.
    const std::string verdict =
        std::string(c.passed() ? "pass" : "FAIL") +
        (c.cutShort() ? " (decided after " + std::to_string(c.run) + " of " + std::to_string(c.episodes) + ")" : "");
    std::snprintf(line, sizeof line, "%-*s  %8s  %6llu  %11.1f  %s\n", static_cast<int>(width), c.name.c_str(),
                  balanced.c_str(), static_cast<unsigned long long>(c.pass), shownReturn(c.mean_return, 1),
                  verdict.c_str());
    out << line;
  }
  if (!reward_note.empty())
    out << "(mean return: " << reward_note << ")\n";
  return out.str();
}

}  // namespace cartpole_qlearning
