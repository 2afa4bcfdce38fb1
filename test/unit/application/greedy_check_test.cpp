// The greedy check during training (greedy_check.h): every episode to the step limit, or not.
#include "cartpole_qlearning/application/greedy_check.h"
#include "cartpole_qlearning/application/greedy_episodes.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/io/yaml_parameters.h"
#include "cartpole_qlearning/simulation/physics_engines.h"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace cartpole_qlearning;

namespace
{
TEST(GreedyCheck, PassesWhenEveryEpisodeReachesTheStepLimit)
{
  TrainingConfig config;
  config.task.max_episode_steps = 5;  // any table holds the pole 5 steps from near upright
  GreedyCheck check(config, 3, greedyCheckSeed(0));
  const QTable table(config.agent.discretiser, config.agent.actions);
  EXPECT_TRUE(check.passes(table));
  EXPECT_EQ(15u, check.stepsRun());
  EXPECT_TRUE(check.passes(table));
  EXPECT_EQ(30u, check.stepsRun());
}

TEST(GreedyCheck, FailsAtTheFirstFallAndLearnsNothing)
{
  TrainingConfig config;
  // An untrained table pushes one way every step (its first action): the pole falls long before 500.
  GreedyCheck check(config, 10, greedyCheckSeed(0));
  QTable table(config.agent.discretiser, config.agent.actions);
  const QTable before = table;
  EXPECT_FALSE(check.passes(table));
  EXPECT_GT(check.stepsRun(), 0u);
  EXPECT_LT(check.stepsRun(), config.task.max_episode_steps);  // one episode, not ten
  EXPECT_EQ(before.values(), table.values());
  EXPECT_THROW(GreedyCheck(config, 0, 0), std::invalid_argument);
}

TEST(GreedyCheck, StartsOfItsOwnApartFromEveryRobots)
{
  EXPECT_NE(greedyCheckSeed(0), 0u);
  EXPECT_GT(greedyCheckSeed(5), robotSeed(5, 999));
}

}  // namespace

TEST(GreedyEpisodes, HoldEachActionForTheDecisionPeriodAsASessionDoes)
{
  TrainingConfig config = readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/swingup.yaml"));
  ASSERT_GT(config.agent.decision_steps, 1u);
  config.limits.max_episodes = 3;
  HeadlessTrainer trainer(config, 0);
  trainer.run();
  const QTable& table = trainer.session().table();

  // The same starts for both: a greedy session stepped by hand, and GreedyEpisodes.
  CartPoleSimulation by_hand = makeSimulation(config.physics, config.engine, config.start_state_bound, 7);
  CartPoleSimulation greedy_sim = makeSimulation(config.physics, config.engine, config.start_state_bound, 7);
  by_hand.setStart(config.task.start(config.start_state_bound));
  greedy_sim.setStart(config.task.start(config.start_state_bound));
  TrainingSession session(config.task, config.agent, 0, false);
  ASSERT_EQ("", session.replaceTable(table));
  GreedyEpisodes greedy(table, config);
  for (int episode = 0; episode < 2; ++episode)
  {
    double effort = session.beginEpisode(by_hand.resetRandom());
    for (;;)
    {
      const Decision decision = session.observe(by_hand.step(effort));
      if (decision.episode_over)
        break;
      effort = decision.effort;
    }
    const GreedyEpisode run = greedy.run(greedy_sim);
    EXPECT_EQ(session.lastEpisode().steps, run.steps);
    EXPECT_EQ(session.lastEpisode().episode_return, run.episode_return) << "episode " << episode;
  }
}
