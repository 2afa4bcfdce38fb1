#include "cartpole_qlearning/learning/cartpole_task.h"

#include <gtest/gtest.h>

#include <cmath>

using cartpole_qlearning::CartPoleState;
using cartpole_qlearning::CartPoleTask;
using cartpole_qlearning::RewardScheme;
using cartpole_qlearning::StepOutcome;
using cartpole_qlearning::TaskParams;

namespace
{
const double kThetaLimit = 12.0 * 2.0 * M_PI / 360.0;

CartPoleTask taskWith(RewardScheme reward)
{
  TaskParams params;
  params.reward = reward;
  return CartPoleTask(params);
}
}  // namespace

TEST(CartPoleTask, TerminatesStrictlyBeyondTheThresholds)
{
  const CartPoleTask task;
  EXPECT_FALSE(task.isTerminal(CartPoleState(2.4, 0, 0, 0)));
  EXPECT_FALSE(task.isTerminal(CartPoleState(-2.4, 0, 0, 0)));
  EXPECT_TRUE(task.isTerminal(CartPoleState(std::nextafter(2.4, 3.0), 0, 0, 0)));
  EXPECT_TRUE(task.isTerminal(CartPoleState(std::nextafter(-2.4, -3.0), 0, 0, 0)));
  EXPECT_FALSE(task.isTerminal(CartPoleState(0, 0, kThetaLimit, 0)));
  EXPECT_FALSE(task.isTerminal(CartPoleState(0, 0, -kThetaLimit, 0)));
  EXPECT_TRUE(task.isTerminal(CartPoleState(0, 0, std::nextafter(kThetaLimit, 1.0), 0)));
  EXPECT_TRUE(task.isTerminal(CartPoleState(0, 0, std::nextafter(-kThetaLimit, -1.0), 0)));
  // Velocities never end an episode.
  EXPECT_FALSE(task.isTerminal(CartPoleState(0, 100, 0, -100)));
}

TEST(CartPoleTask, TruncatesAtTheStepLimitNotBefore)
{
  const CartPoleTask task;
  const CartPoleState upright = CartPoleState::Zero();
  EXPECT_FALSE(task.evaluate(upright, 499, 0.0).done());
  const StepOutcome last = task.evaluate(upright, 500, 0.0);
  EXPECT_TRUE(last.truncated);
  EXPECT_FALSE(last.terminated);
  // Falling on the last step is a fall: no bootstrapping on it.
  const StepOutcome fall = task.evaluate(CartPoleState(0, 0, 0.5, 0), 500, 0.0);
  EXPECT_TRUE(fall.terminated);
  EXPECT_FALSE(fall.truncated);
}

TEST(CartPoleTask, GymnasiumRewardIsOneEveryStepIncludingTheFall)
{
  const CartPoleTask task = taskWith(RewardScheme::Gymnasium);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState::Zero(), 1, 0.0).reward);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState(3, 0, 0, 0), 7, 0.0).reward);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState::Zero(), 500, 0.0).reward);
}

TEST(CartPoleTask, SeedRewardIsMinusOneOnTheFall)
{
  const CartPoleTask task = taskWith(RewardScheme::Seed);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState::Zero(), 1, 0.0).reward);
  EXPECT_EQ(-1.0, task.evaluate(CartPoleState(0, 0, -0.3, 0), 9, 0.0).reward);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState::Zero(), 500, 0.0).reward);  // truncation is no fall
}

TEST(CartPoleTask, SuttonBartoRewardIsZeroUntilTheFall)
{
  const CartPoleTask task = taskWith(RewardScheme::SuttonBarto);
  EXPECT_EQ(0.0, task.evaluate(CartPoleState::Zero(), 1, 0.0).reward);
  EXPECT_EQ(-1.0, task.evaluate(CartPoleState(-2.5, 0, 0, 0), 3, 0.0).reward);
  EXPECT_EQ(0.0, task.evaluate(CartPoleState::Zero(), 500, 0.0).reward);
}

TEST(CartPoleTask, BadParametersAreRefused)
{
  TaskParams params;
  params.max_episode_steps = 0;
  EXPECT_THROW(CartPoleTask task(params), std::invalid_argument);
  params = TaskParams();
  params.theta_threshold_deg = 95.0;
  EXPECT_NE(std::string::npos, params.validate().find("theta_threshold_deg = 95")) << params.validate();
  EXPECT_THROW(cartpole_qlearning::rewardSchemeFromString("shaped"), std::invalid_argument);
}

TEST(CartPoleTask, AliveQuadraticCostsTheCartsPlaceAndSpeedAndNothingOnTheFall)
{
  TaskParams params;
  params.reward = RewardScheme::AliveQuadratic;
  params.x_cost = 0.5;
  params.x_dot_cost = 0.25;
  const CartPoleTask task(params);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState::Zero(), 1, 0.0).reward);
  EXPECT_DOUBLE_EQ(1.0 - 0.5 * 0.04 - 0.25 * 0.36, task.evaluate(CartPoleState(-0.2, 0.6, 0.0, 0.0), 1, 0.0).reward);
  EXPECT_EQ(0.0, task.evaluate(CartPoleState(0.5, 1.0, 0.3, 0.0), 4, 0.0).reward);  // the fall
  // Without costs it is alive's, bit for bit.
  TaskParams plain;
  plain.reward = RewardScheme::AliveQuadratic;
  EXPECT_EQ(1.0, CartPoleTask(plain).evaluate(CartPoleState(0.7, -0.4, 0.1, 0.2), 3, 0.0).reward);
  EXPECT_EQ(RewardScheme::AliveQuadratic, cartpole_qlearning::rewardSchemeFromString("alive_quadratic"));
  EXPECT_EQ("alive_quadratic", cartpole_qlearning::toString(RewardScheme::AliveQuadratic));
  // The costs belong to alive_quadratic alone, and are never negative.
  TaskParams other;
  other.x_cost = 0.1;
  EXPECT_NE(std::string::npos, other.validate().find("only alive_quadratic reads them")) << other.validate();
  params.x_dot_cost = -1.0;
  EXPECT_NE(std::string::npos, params.validate().find("x_dot_cost = -1")) << params.validate();
}

TEST(CartPoleTask, TheSolvedRewardScoresEpisodesWhateverTheLearnerTrainsOn)
{
  TaskParams params;
  params.reward = RewardScheme::AliveQuadratic;
  params.x_cost = 1.0;
  params.max_episode_steps = 1000;
  params.solved_mean_return = 950.0;
  // Unset: the score is the training reward.
  EXPECT_EQ(RewardScheme::AliveQuadratic, params.scoreReward());
  const StepOutcome unscored = CartPoleTask(params).evaluate(CartPoleState(0.5, 0.0, 0.0, 0.0), 1, 0.0);
  EXPECT_EQ(unscored.reward, unscored.score);
  // Set: each step is worth the solved reward's (v5's +1 while alive) to the return, the
  // training reward's to the learner.
  params.solved_reward = RewardScheme::Alive;
  const CartPoleTask task(params);
  const StepOutcome step = task.evaluate(CartPoleState(0.5, 0.0, 0.0, 0.0), 1, 0.0);
  EXPECT_DOUBLE_EQ(0.75, step.reward);
  EXPECT_EQ(1.0, step.score);
  const StepOutcome fall = task.evaluate(CartPoleState(0.5, 0.0, 0.3, 0.0), 2, 0.0);
  EXPECT_EQ(0.0, fall.reward);
  EXPECT_EQ(0.0, fall.score);
  EXPECT_TRUE(params.solvable());
  // A reward that cannot reach the mark as a score: centred trains, alive judges.
  TaskParams centred;
  centred.reward = RewardScheme::Centred;
  EXPECT_FALSE(centred.solvable());
  centred.solved_reward = RewardScheme::Alive;
  EXPECT_TRUE(centred.solvable());
  EXPECT_EQ(500.0, centred.largestReturn());
}
