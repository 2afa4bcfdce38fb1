#include "test_support.h"
#include "cartpole_qlearning/application/headless_trainer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

using cartpole_qlearning::test::bitIdentical;
using namespace cartpole_qlearning;

namespace
{
TrainingConfig shippedConfig()
{
  return readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/cartpole.yaml"));
}

}  // namespace

TEST(HeadlessTrainer, DefaultConfigSolvesCartPoleOnSeedsZeroToNineInAMedianOfAtMost300Episodes)
{
  // Deterministic per seed, and milliseconds per run, so the whole promise is checked here.
  std::vector<std::uint64_t> episodes;
  for (std::uint64_t seed = 0; seed < 10; ++seed)
  {
    HeadlessTrainer trainer(shippedConfig(), seed);
    const TrainingResult result = trainer.run();
    EXPECT_TRUE(result.solved) << "seed " << seed;
    EXPECT_GE(trainer.session().lastEpisode().mean_return_window, 475.0) << "seed " << seed;
    EXPECT_EQ(result.episodes, trainer.session().table().episodes);
    EXPECT_EQ(result.steps, trainer.session().table().steps);
    episodes.push_back(result.episodes);
  }
  std::sort(episodes.begin(), episodes.end());
  const double median = (episodes[4] + episodes[5]) / 2.0;
  EXPECT_LE(median, 300.0);
}

TEST(HeadlessTrainer, TilesConfigSolvesSeedsZeroToNineInAMedianOfAtMost150Episodes)
{
  const TrainingConfig config = readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/tiles.yaml"));
  ASSERT_EQ(FeatureKind::Tiles, config.agent.features);
  std::vector<std::uint64_t> episodes;
  for (std::uint64_t seed = 0; seed < 10; ++seed)
  {
    HeadlessTrainer trainer(config, seed);
    const TrainingResult result = trainer.run();
    EXPECT_TRUE(result.solved) << "seed " << seed;
    EXPECT_EQ(FeatureKind::Tiles, trainer.session().table().features().kind);
    episodes.push_back(result.episodes);
  }
  std::sort(episodes.begin(), episodes.end());
  EXPECT_LE((episodes[4] + episodes[5]) / 2.0, 150.0);
}

TEST(HeadlessTrainer, SameSeedGivesTheSameTableBitForBit)
{
  TrainingConfig config = shippedConfig();
  config.limits.max_episodes = 150;
  HeadlessTrainer a(config, 7);
  HeadlessTrainer b(config, 7);
  HeadlessTrainer c(config, 8);
  const TrainingResult ra = a.run();
  const TrainingResult rb = b.run();
  c.run();
  EXPECT_EQ(ra.steps, rb.steps);
  EXPECT_TRUE(bitIdentical(a.session().table().values(), b.session().table().values()));
  EXPECT_FALSE(bitIdentical(a.session().table().values(), c.session().table().values()));
}

TEST(HeadlessTrainer, AnEnsembleTrainsEachTableOnItsOwnEpisodesAndTheTableIsTheirMean)
{
  TrainingConfig config = readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/tiles.yaml"));
  config.agent.ensemble = 2;
  config.limits.stop_when_solved = false;
  config.limits.max_episodes = 1;
  HeadlessTrainer one(config, 3);
  one.run();
  const auto nonzero = [](const QTable& table) {
    return std::count_if(table.values().begin(), table.values().end(), [](double v) { return v != 0.0; });
  };
  ASSERT_EQ(2u, one.session().ensembleTables().size());
  EXPECT_GT(nonzero(one.session().ensembleTables()[0]), 0);
  EXPECT_EQ(0, nonzero(one.session().ensembleTables()[1]));  // its turn has not come

  config.limits.max_episodes = 60;
  HeadlessTrainer sixty(config, 3);
  sixty.run();
  const std::vector<QTable>& tables = sixty.session().ensembleTables();
  EXPECT_GT(nonzero(tables[1]), 0);
  EXPECT_FALSE(bitIdentical(tables[0].values(), tables[1].values()));
  const QTable& mean = sixty.session().table();
  EXPECT_EQ(60u, mean.episodes);
  for (std::size_t i = 0; i < mean.values().size(); ++i)
    ASSERT_NEAR((tables[0].values()[i] + tables[1].values()[i]) / 2.0, mean.values()[i], 1e-12) << "weight " << i;
}

TEST(HeadlessTrainer, EpisodeStatisticsAddUp)
{
  TrainingConfig config = shippedConfig();
  config.task.solved_window = 5;
  config.limits.max_episodes = 12;
  config.limits.stop_when_solved = false;
  HeadlessTrainer trainer(config, 1);
  std::vector<EpisodeSummary> episodes;
  trainer.run([&](const EpisodeSummary& s) { episodes.push_back(s); });
  ASSERT_EQ(12u, episodes.size());
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < episodes.size(); ++i)
  {
    total += episodes[i].steps;
    EXPECT_EQ(i + 1, episodes[i].episode);
    EXPECT_EQ(total, episodes[i].total_steps);
    EXPECT_EQ(static_cast<double>(episodes[i].steps), episodes[i].episode_return);  // +1 per step
    EXPECT_NE(episodes[i].terminated, episodes[i].truncated);
    double sum = 0;
    const std::size_t first = i + 1 >= 5 ? i + 1 - 5 : 0;
    for (std::size_t j = first; j <= i; ++j)
      sum += episodes[j].episode_return;
    EXPECT_DOUBLE_EQ(sum / static_cast<double>(i + 1 - first), episodes[i].mean_return_window);
  }
}

TEST(HeadlessTrainer, RunUntilEndsWhereTheCallerSaysOrAtOnceWhenStopped)
{
  TrainingConfig config = shippedConfig();
  config.limits.max_episodes = 3;  // runUntil leaves the limits to the caller
  HeadlessTrainer trainer(config, 2);
  std::uint64_t seen = 0;
  const TrainingResult result = trainer.runUntil([&](const EpisodeSummary& s) {
    ++seen;
    return s.episode == 7;
  });
  EXPECT_EQ(7u, seen);
  EXPECT_EQ(7u, result.episodes);
  EXPECT_EQ(7u, trainer.session().table().episodes);

  // Stopped (Ctrl-C): no further episode ends, and the table keeps its counters.
  const std::atomic<bool> stop{true};
  const TrainingResult stopped = trainer.runUntil([](const EpisodeSummary&) { return false; }, &stop);
  EXPECT_EQ(0u, stopped.episodes);
  EXPECT_EQ(7u, trainer.session().table().episodes);
}

TEST(HeadlessTrainer, AnEvaluatingTrainerLearnsNothing)
{
  TrainingConfig config = shippedConfig();
  HeadlessTrainer evaluator(config, 0, 2, false);
  const std::vector<double> before = evaluator.session().table().values();
  evaluator.runUntil([](const EpisodeSummary& s) { return s.episode == 4; });
  EXPECT_TRUE(bitIdentical(before, evaluator.session().table().values()));
  EXPECT_EQ(4u, evaluator.session().episodesEnded());
}

TEST(TrainingSession, TruncationBootstrapsAndAFallDoesNot)
{
  TaskParams task;
  task.max_episode_steps = 1;
  AgentParams agent;
  agent.gamma = 0.5;
  agent.epsilon.type = ScheduleType::Constant;
  agent.epsilon.start = agent.epsilon.min = 0.0;
  agent.alpha.type = ScheduleType::Constant;
  agent.alpha.start = agent.alpha.min = 1.0;
  TrainingSession session(task, agent, 0);

  const Discretiser& d = session.agent().discretiser();
  const CartPoleState upright = CartPoleState::Zero();
  const CartPoleState fallen(0.0, 0.0, 0.5, 0.0);
  QTable table(agent.discretiser, agent.actions);
  table.at(d.index(upright), 0) = 8.0;  // so that the bootstrap term is visible
  table.at(d.index(fallen), 0) = 8.0;
  ASSERT_EQ("", session.replaceTable(table));

  // Upright -> upright, truncated after one step: Q = 1 + 0.5 * 8.
  EXPECT_EQ(-10.0, session.beginEpisode(upright));
  Decision decision = session.observe(upright);
  EXPECT_TRUE(decision.episode_over);
  EXPECT_TRUE(decision.outcome.truncated);
  EXPECT_DOUBLE_EQ(1.0 + 0.5 * 8.0, session.table().at(d.index(upright), 0));

  // Upright -> fallen: Q = 1, no bootstrap on the fallen state's 8.
  session.beginEpisode(upright);
  decision = session.observe(fallen);
  EXPECT_TRUE(decision.outcome.terminated);
  EXPECT_DOUBLE_EQ(1.0, session.table().at(d.index(upright), 0));
  EXPECT_EQ(2u, session.table().episodes);
}

TEST(TrainingSession, ADecisionPeriodHoldsTheActionAndLearnsTheSummedRewardDiscountedOnce)
{
  TaskParams task;
  task.max_episode_steps = 4;
  AgentParams agent;
  agent.gamma = 0.5;
  agent.decision_steps = 3;
  agent.epsilon.type = ScheduleType::Constant;
  agent.epsilon.start = agent.epsilon.min = 0.0;
  agent.alpha.type = ScheduleType::Constant;
  agent.alpha.start = agent.alpha.min = 1.0;
  TrainingSession session(task, agent, 0);

  const Discretiser& d = session.agent().discretiser();
  const CartPoleState upright = CartPoleState::Zero();
  QTable table(agent.discretiser, agent.actions);
  table.at(d.index(upright), 0) = 8.0;
  ASSERT_EQ("", session.replaceTable(table));

  EXPECT_EQ(-10.0, session.beginEpisode(upright));
  // Within the period: the same action, nothing learnt yet.
  for (int step = 1; step <= 2; ++step)
  {
    const Decision decision = session.observe(upright);
    EXPECT_FALSE(decision.episode_over);
    EXPECT_EQ(0u, decision.action);
    EXPECT_DOUBLE_EQ(8.0, session.table().at(d.index(upright), 0)) << "step " << step;
  }
  // The third step ends the period: the three rewards of 1 summed, gamma once: 3 + 0.5 * 8.
  session.observe(upright);
  EXPECT_DOUBLE_EQ(3.0 + 0.5 * 8.0, session.table().at(d.index(upright), 0));
  EXPECT_EQ(3u, session.table().steps);
  // Truncated one step into the next period: that step's reward, bootstrapped once: 1 + 0.5 * 7.
  const Decision last = session.observe(upright);
  EXPECT_TRUE(last.outcome.truncated);
  EXPECT_DOUBLE_EQ(1.0 + 0.5 * 7.0, session.table().at(d.index(upright), 0));
  EXPECT_EQ(4u, session.table().steps);
}

TEST(TrainingSession, EvaluationActsGreedilyAndLearnsNothing)
{
  TrainingConfig config = shippedConfig();
  HeadlessTrainer trainer(config, 0);
  trainer.run();
  TrainingSession evaluator(config.task, config.agent, 0, false);
  ASSERT_EQ("", evaluator.replaceTable(trainer.session().table()));
  const std::vector<double> before = evaluator.table().values();

  CartPoleSimulation sim(config.physics, config.start_state_bound, 99);
  double effort = evaluator.beginEpisode(sim.resetRandom());
  Decision decision;
  do
  {
    decision = evaluator.observe(sim.step(effort));
    effort = decision.effort;
  } while (!decision.episode_over);
  EXPECT_TRUE(bitIdentical(before, evaluator.table().values()));
  EXPECT_EQ(0.0, evaluator.lastEpisode().epsilon);
  EXPECT_GT(evaluator.lastEpisode().steps, 100u);  // a solved table balances a fresh start for long
}

TEST(TrainingSession, ALoadedTableResumesItsSchedules)
{
  const AgentParams agent;
  TrainingSession session(TaskParams(), agent, 0);
  QTable table(agent.discretiser, agent.actions);
  table.episodes = 400;
  ASSERT_EQ("", session.replaceTable(table));
  session.beginEpisode(CartPoleState::Zero());
  Decision d;
  do
    d = session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));
  while (!d.episode_over);
  EXPECT_DOUBLE_EQ(session.agent().epsilon(400), session.lastEpisode().epsilon);
  EXPECT_DOUBLE_EQ(agent.epsilon.min, session.lastEpisode().epsilon);  // the floor, not a fresh start
  EXPECT_EQ(401u, session.table().episodes);
}

// A table loaded mid-episode (the load service while training, as the tutorial does it) counts
// from its own steps: when that episode ends, the session's total is the table's, so the run's
// last line and the table it saves agree. (The episode's steps before the load were learnt by
// the table replaced, not by this one.)
TEST(TrainingSession, ATableLoadedMidEpisodeKeepsTheStepCountsInStep)
{
  const AgentParams agent;
  TrainingSession session(TaskParams(), agent, 0);
  QTable saved(agent.discretiser, agent.actions);
  saved.episodes = 7;
  saved.steps = 1000;
  session.beginEpisode(CartPoleState::Zero());
  for (int i = 0; i < 5; ++i)
    ASSERT_FALSE(session.observe(CartPoleState(0.0, 0.0, 0.01, 0.0)).episode_over);
  ASSERT_EQ("", session.resume(saved, {}));
  EXPECT_EQ(1000u, session.lastEpisode().total_steps);
  Decision d;
  do
    d = session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));
  while (!d.episode_over);
  EXPECT_EQ(1001u, session.table().steps);  // one step learnt after the load: the fall
  EXPECT_EQ(session.table().steps, session.lastEpisode().total_steps);
  EXPECT_EQ(6u, session.lastEpisode().steps);  // the episode itself was 6 steps long
  EXPECT_EQ(8u, session.lastEpisode().episode);
  // The next episode counts whole.
  session.beginEpisode(CartPoleState::Zero());
  do
    d = session.observe(CartPoleState(0.0, 0.0, 1.0, 0.0));
  while (!d.episode_over);
  EXPECT_EQ(session.table().steps, session.lastEpisode().total_steps);
}

TEST(CartPoleSimulation, RandomStartsStayWithinTheBoundAndFollowTheSeed)
{
  CartPoleSimulation a(CartPoleParams(), 0.05, 5);
  CartPoleSimulation b(CartPoleParams(), 0.05, 5);
  for (int i = 0; i < 1000; ++i)
  {
    const CartPoleState s = a.resetRandom();
    EXPECT_EQ(s, b.resetRandom());
    EXPECT_LE(s.cwiseAbs().maxCoeff(), 0.05);
  }
  a.reset(CartPoleState(0, 0, 0, 0));
  a.step(25.0);
  EXPECT_EQ(10.0, a.appliedForce());
}

TEST(TrainingSession, ATrainedTableSaysTheStepAndConfigurationItLearntWith)
{
  TrainingSession session(TaskParams(), AgentParams(), 0);
  session.stampTables(0.02, "learning: {gamma: 0.99}\n");
  EXPECT_EQ(0.02, session.table().tau);
  EXPECT_EQ("learning: {gamma: 0.99}\n", session.table().trained_with);
  // A table trained further from here is this configuration's, whatever it said before.
  QTable other(AgentParams().featureParams(), AgentParams().actions);
  other.trained_with = "learning: {gamma: 0.5}\n";
  other.tau = 0.02;
  ASSERT_EQ("", session.replaceTable(other));
  EXPECT_EQ("learning: {gamma: 0.99}\n", session.table().trained_with);
  ASSERT_EQ("", session.resume(QTable(AgentParams().featureParams(), AgentParams().actions), {}));
  EXPECT_EQ(0.02, session.table().tau);
  // Values learnt at another step do not fit, though the shape does.
  other.tau = 0.01;
  EXPECT_EQ("tau 0.01 differs from 0.02", session.replaceTable(other));
  EXPECT_EQ("learning: {gamma: 0.99}\n", session.table().trained_with);
}

TEST(TrainingSession, AnEvaluatedTableKeepsWhatItSaysOfItsTraining)
{
  TrainingSession session(TaskParams(), AgentParams(), 0, false);
  session.stampTables(0.02, "task: {}\n");
  QTable trained(AgentParams().featureParams(), AgentParams().actions);
  trained.trained_with = "learning: {gamma: 0.5}\n";
  ASSERT_EQ("", session.replaceTable(trained));
  EXPECT_EQ("learning: {gamma: 0.5}\n", session.table().trained_with);
  EXPECT_EQ(0.0, session.table().tau);
}

TEST(TrainingSession, TheLearnerTrainsOnTheRewardAndTheReturnsAreTheSolvedRewards)
{
  // alive_quadratic trains (a cart off centre is worth less than 1 a step), alive scores: the
  // episode's return and the solved window count steps alive, as InvertedPendulum-v5's do.
  TaskParams task;
  task.reward = RewardScheme::AliveQuadratic;
  task.x_cost = 1.0;
  task.solved_reward = RewardScheme::Alive;
  task.max_episode_steps = 3;
  task.solved_window = 1;
  task.solved_mean_return = 3.0;
  AgentParams agent;
  agent.gamma = 0.0;  // Q is the last reward itself
  agent.epsilon.type = ScheduleType::Constant;
  agent.epsilon.start = agent.epsilon.min = 0.0;
  agent.alpha.type = ScheduleType::Constant;
  agent.alpha.start = agent.alpha.min = 1.0;
  TrainingSession session(task, agent, 0);
  const Discretiser& d = session.agent().discretiser();
  const CartPoleState off_centre(0.5, 0.0, 0.0, 0.0);
  session.beginEpisode(off_centre);
  Decision decision;
  for (int step = 0; step < 3; ++step)
    decision = session.observe(off_centre);
  ASSERT_TRUE(decision.episode_over);
  EXPECT_DOUBLE_EQ(0.75, decision.outcome.reward);
  EXPECT_EQ(1.0, decision.outcome.score);
  const std::size_t row = d.index(off_centre);
  double learnt = 0.0;
  for (std::size_t a = 0; a < agent.actions.size(); ++a)
    learnt = std::max(learnt, session.table().at(row, a));
  EXPECT_DOUBLE_EQ(0.75, learnt);
  EXPECT_EQ(3.0, session.lastEpisode().episode_return);
  EXPECT_TRUE(session.lastEpisode().solved);
}

TEST(TrainingSession, APredictionOfTheDelayIsForAGreedySessionOnly)
{
  const TrainingConfig config;
  TrainingSession learning(config.task, config.agent, 0, true);
  EXPECT_NE(learning.predictDelay(config.physics, 1).find("training learns from the states it observes"),
            std::string::npos);
  EXPECT_EQ(learning.predictedDelaySteps(), 0u);
  EXPECT_EQ(learning.predictDelay(config.physics, 0), "");

  TrainingSession greedy(config.task, config.agent, 0, false);
  EXPECT_NE(greedy.predictDelay(config.physics, kMaxPredictedDelaySteps + 1).find("is not allowed"), std::string::npos);
  EXPECT_EQ(greedy.predictedDelaySteps(), 0u);
  ASSERT_EQ(greedy.predictDelay(config.physics, 1), "");
  EXPECT_EQ(greedy.predictedDelaySteps(), 1u);

  // The first decision is made for the start advanced one step under no command, the next for the
  // state advanced under the command just sent: the same action as a session shown those states.
  TrainingSession shown(config.task, config.agent, 0, false);
  QTable table(config.agent.featureParams(), config.agent.actions);
  std::vector<double> values(table.values().size());
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<double>((i * 7919) % 13) - 6.0;
  table.setValues(values);
  ASSERT_EQ(greedy.replaceTable(table), "");
  ASSERT_EQ(shown.replaceTable(table), "");
  // And not the action a session that does not predict takes on every state: the prediction counts.
  TrainingSession observing(config.task, config.agent, 0, false);
  ASSERT_EQ(observing.replaceTable(table), "");
  const CartPoleDynamics model(config.physics);
  CartPoleState state;
  state << 0.02, -0.1, 0.04, 0.3;
  double effort = greedy.beginEpisode(state);
  EXPECT_EQ(effort, shown.beginEpisode(model.step(state, 0.0)));
  int differs = effort != observing.beginEpisode(state);
  int decisions = 0;
  for (int step = 0; step < 20; ++step)
  {
    state = model.step(state, effort);
    const Decision decision = greedy.observe(state);
    const Decision expected = shown.observe(model.step(state, effort));
    const Decision observed = observing.observe(state);
    if (decision.episode_over || expected.episode_over || observed.episode_over)
      break;
    EXPECT_EQ(decision.effort, expected.effort) << "step " << step;
    differs += decision.effort != observed.effort;
    ++decisions;
    effort = decision.effort;
  }
  EXPECT_GE(decisions, 5);
  EXPECT_GT(differs, 0);
}
