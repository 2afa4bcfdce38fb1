#include "cartpole_qlearning/application/suite_runner.h"

#include "cartpole_qlearning/application/greedy_episodes.h"
#include "cartpole_qlearning/simulation/engine_registry.h"
#include "cartpole_qlearning/simulation/physics_engines.h"

#ifdef __linux__
#include <sched.h>
#endif

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

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

CaseResult startResult(const SuiteCase& suite_case, std::uint64_t episodes, std::uint64_t target)
{
  CaseResult result;
  result.name = suite_case.name;
  result.pass = suite_case.pass;
  result.episodes = episodes;
  result.target = target;
  return result;
}

// Counts a greedy episode into its case's result (its return into returns); index: the episode's
// place in the case's draw.
void countEpisode(const GreedyEpisode& episode, std::uint32_t index, CaseResult& result, double& returns)
{
  result.steps += episode.steps;
  result.balanced += episode.balanced;
  if (!episode.balanced)
    result.fallen.push_back(index);
  returns += episode.episode_return;
  ++result.run;
}

// The balanced episodes a case is decided against in this run.
std::uint64_t targetOf(const SuiteRun& how, const SuiteCase& suite_case)
{
  return how.target ? how.target(suite_case) : suite_case.pass;
}

// The falls after which a case can no longer reach its target.
std::uint64_t fallsToFail(const CaseResult& result)
{
  const std::uint64_t decided_at = result.decidedAgainst();
  return result.episodes >= decided_at ? result.episodes - decided_at + 1 : 0;
}

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
  {
    simulation = std::make_unique<CartPoleSimulation>(makeSimulation(
        suite_case.physics, suite_case.engine, suite_case.start_state_bound, seed, suite_case.perturbations));
    simulation->setStart(config.task.start(suite_case.start_state_bound));
  }
  // Decided once target episodes balanced, or once more fell than that allows.
  const std::uint64_t decided_at = result.decidedAgainst();
  const std::uint64_t falls_to_fail = fallsToFail(result);
  const auto decided = [&]() {
    return stop_when_decided && (result.balanced >= decided_at || result.run - result.balanced >= falls_to_fail);
  };
  // Decided is asked after each episode run here (a case started afresh runs at least one); an
  // abandoned case stops before its next.
  for (std::uint64_t e = result.run; e < episodes && !(e > 0 && decided()) && !(abandoned && abandoned()); ++e)
    countEpisode(greedy.run(*simulation), static_cast<std::uint32_t>(e), result, returns);
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
    simulation.setStart(config.task.start(suite_case.start_state_bound));
    for (std::uint32_t before = 0; before < e; ++before)
      simulation.resetRandom();
    const std::uint64_t balanced = result.balanced;
    countEpisode(greedy.run(simulation), e, result, returns);
    if (result.balanced > balanced || result.fallen.size() >= falls_to_stop)
      break;
  }
  result.mean_return = result.run > 0 ? returns / static_cast<double>(result.run) : 0.0;
  return result;
}

namespace
{
// The cases' indices in the order to run them: how.order, checked, or the suite's own.
std::vector<std::size_t> runOrder(const SuiteRun& how, const RobustnessSuite& suite)
{
  std::vector<std::size_t> order = how.order;
  if (order.empty())
    for (std::size_t i = 0; i < suite.cases.size(); ++i)
      order.push_back(i);
  if (order.size() != suite.cases.size() || std::set<std::size_t>(order.begin(), order.end()).size() != order.size() ||
      *std::max_element(order.begin(), order.end()) >= suite.cases.size())
    throw std::invalid_argument("evaluateSuite: the order must name each of the suite's cases once");
  return order;
}

// The case the probe tries: of the cases whose episodes run in any order, the one failed by the
// fewest falls (`needed`; the first in `order` of those), unless it rests. suite.cases.size(): none.
std::size_t probedCase(const RobustnessSuite& suite, const SuiteRun& how, const std::vector<std::size_t>& order,
                       FallenEpisodes& falls, std::uint64_t& needed)
{
  std::size_t index = suite.cases.size();
  for (const std::size_t i : order)
  {
    const SuiteCase& c = suite.cases[i];
    FallenEpisodes::Case& memory = falls.by_case[i];
    const std::uint64_t falls_to_fail = fallsToFail(startResult(c, suite.episodes, targetOf(how, c)));
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
  return index;
}

// The probe (SuiteRun::falls): a table that fell on an episode after the last training episode
// mostly falls there again after this one, and a case that needs every episode (nominal) is
// failed by one fall, where the case that failed last (first in `order`) may need several
// long episodes to fall as often as fails it (all_at_once: 6 of 100, each balanced episode
// before them 3000 steps). Seed 0's robust.yaml run: 350 of 389 tables sampled that failed
// the suite failed nominal too; 1,646 of its evaluations were then decided by the probe at
// about 400 greedy steps each, where all_at_once took 33,000 (docs/benchmarks.md).
// True when it decided the suite: `result` then holds the case it found short of its target.
bool probe(const QTable& table, const TrainingConfig& judged, const RobustnessSuite& suite, const SuiteRun& how,
           const std::vector<std::size_t>& order, FallenEpisodes& falls, SuiteResult& result)
{
  falls.by_case.resize(suite.cases.size());
  std::uint64_t needed = 0;
  const std::size_t index = probedCase(suite, how, order, falls, needed);
  if (index == suite.cases.size())
    return false;
  const SuiteCase& c = suite.cases[index];
  FallenEpisodes::Case& memory = falls.by_case[index];
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
  CaseResult probed = evaluateEpisodes(table, judged, c, suite.episodes, suite.seed, which, needed, targetOf(how, c),
                                       how.predict_delay_steps);
  memory.fallen = probed.fallen;
  if (probed.fallen.size() >= needed)
  {
    result.cases.push_back(std::move(probed));
    result.probed = true;
    return true;
  }
  // It balanced one: the cases run in order. A case whose first episode tried balanced rests a
  // while (a table that passes it would pay a balanced episode for nothing at every evaluation).
  if (probed.fallen.empty())
    memory.rest = FallenEpisodes::kRest;
  return false;
}

// The threads to run the cases on: how.threads, or one per core this process may use; one when an
// engine cannot be made on several at once (MuJoCo's XML loading).
std::size_t threadsFor(const RobustnessSuite& suite, const SuiteRun& how, std::size_t cases)
{
  std::size_t threads = std::min<std::size_t>(how.threads > 0 ? how.threads : usableCores(), cases);
  if (std::any_of(suite.cases.begin(), suite.cases.end(),
                  [](const SuiteCase& c) { return !engineOf(c.engine).makes_in_parallel; }))
    threads = 1;
  return threads;
}

// Runs the cases in `order` side by side: each result at its position in `order`. With
// how.stop_at_first_failure, `kept` is the number of positions up to the first that fell short of
// its target; else every position.
std::vector<CaseResult> runCases(const QTable& table, const TrainingConfig& judged, const RobustnessSuite& suite,
                                 const SuiteRun& how, const std::vector<std::size_t>& order, std::size_t& kept)
{
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
            runCase(table, judged, c, suite.episodes, suite.seed, how.stop_cases_when_decided, targetOf(how, c),
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
  const std::size_t threads = threadsFor(suite, how, order.size());
  std::vector<std::thread> helpers;
  for (std::size_t t = 1; t < threads; ++t)
    helpers.emplace_back(work);
  work();
  for (std::thread& helper : helpers)
    helper.join();
  if (error)
    std::rethrow_exception(error);
  kept = how.stop_at_first_failure ? std::min(first_failure.load() + 1, order.size()) : order.size();
  return results;
}
}  // namespace

SuiteResult evaluateSuite(const QTable& table, const TrainingConfig& config, const RobustnessSuite& suite,
                          const SuiteRun& how)
{
  TrainingConfig judged = config;
  judged.task.max_episode_steps = suite.max_episode_steps;
  const std::vector<std::size_t> order = runOrder(how, suite);

  SuiteResult result;
  result.cases_in_suite = suite.cases.size();
  const RewardScheme score = config.task.scoreReward();
  if (score != RewardScheme::Gymnasium)
    result.reward_note = toString(score) + "'s reward, " + rewardMeaning(score);

  FallenEpisodes* const falls = how.stop_at_first_failure ? how.falls : nullptr;
  if (falls != nullptr && probe(table, judged, suite, how, order, *falls, result))
    return result;
  if (how.progress != nullptr)
    how.progress->by_case.resize(suite.cases.size());

  std::size_t kept = 0;
  std::vector<CaseResult> results = runCases(table, judged, suite, how, order, kept);
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
}  // namespace cartpole_qlearning
