// The greedy check during training (greedy_check.h): every episode to the step limit, or not.
#include "cartpole_qlearning/application/greedy_check.h"
#include "cartpole_qlearning/application/headless_trainer.h"

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
