// The Control Suite's cart-pole tasks (task/kind balance, swingup, swingup_sparse): rewards checked
// against values worked out by hand from the definitions in dm_control's suite/cartpole.py and
// utils/rewards.py (tolerance), their starts, and episodes that never end but on the clock.
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/features.h"
#include "cartpole_qlearning/learning/training_config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

using namespace cartpole_qlearning;

namespace
{
CartPoleTask taskOf(TaskKind kind)
{
  TaskParams params;
  params.kind = kind;
  params.max_episode_steps = kSuiteEpisodeSteps;
  return CartPoleTask(params);
}

// tolerance(v, margin=m) with the gaussian sigmoid and value_at_margin 0.1, worked out by hand:
// exp(-0.5 (d sqrt(-2 ln 0.1))^2) = 0.1^(d^2), d = v / m.
const double kTolAtHalfMargin = std::pow(0.1, 0.25);  // 0.5623413251903491

TrainingConfig configOf(const std::string& yaml)
{
  return readTrainingConfig(*parseYamlParameters(yaml, "test.yaml"));
}
}  // namespace

TEST(SuiteTask, KindsReadAndWriteByName)
{
  for (const char* name : {"cartpole_v1", "balance", "swingup", "swingup_sparse"})
    EXPECT_EQ(name, toString(taskKindFromString(name)));
  EXPECT_THROW(taskKindFromString("swing_up"), std::invalid_argument);
  EXPECT_FALSE(isSuiteTask(TaskParams().kind));
}

TEST(SuiteTask, SmoothRewardMatchesHandWorkedValues)
{
  const CartPoleTask swingup = taskOf(TaskKind::Swingup);
  const auto reward = [&](double x, double theta, double theta_dot, double effort) {
    return swingup.evaluate(CartPoleState(x, 0.3, theta, theta_dot), 1, effort).reward;
  };
  // Upright, centred, at rest, no control: every factor 1.
  EXPECT_DOUBLE_EQ(1.0, reward(0.0, 0.0, 0.0, 0.0));
  // Hanging: upright = (cos(pi) + 1) / 2 = 0.
  EXPECT_NEAR(0.0, reward(0.0, M_PI, 0.0, 0.0), 1e-15);
  // Level (upright 1/2); x at the margin 2 m: centred (1 + 0.1) / 2 = 0.55; theta_dot at the margin
  // 5 rad/s: 0.55; control 5 N / 10 = 0.5: (4 + 1 - 0.25) / 5 = 0.95. 0.5 x 0.95 x 0.55 x 0.55.
  EXPECT_NEAR(0.1436875, reward(2.0, M_PI / 2, 5.0, 5.0), 1e-12);
  // cos(pi/3) = 0.5: upright 0.75; x = -1 and theta_dot = -2.5 are half their margins:
  // (1 + 0.1^0.25) / 2 each; control -1 (full effort): quadratic sigmoid 0 at the margin: 4/5.
  const double half = (1.0 + kTolAtHalfMargin) / 2.0;
  EXPECT_NEAR(0.75 * 0.8 * half * half, reward(-1.0, M_PI / 3, -2.5, -10.0), 1e-12);
  EXPECT_NEAR(0.36613656245963044, reward(-1.0, M_PI / 3, -2.5, -10.0), 1e-12);
  // Beyond the control's margin the quadratic sigmoid stays 0: the same 4/5 as full effort.
  EXPECT_DOUBLE_EQ(reward(-1.0, M_PI / 3, -2.5, -10.0), reward(-1.0, M_PI / 3, -2.5, -15.0));
  // A whole turn further on is the same pole: cos(2 pi + 0.1) = cos(0.1); x = 1 (0.1^0.25 again);
  // theta_dot = -1: 0.1^(1/25).
  const double expected = (std::cos(0.1) + 1.0) / 2.0 * 1.0 * (1.0 + std::pow(0.1, 0.04)) / 2.0 * half;
  EXPECT_NEAR(expected, reward(1.0, 2 * M_PI + 0.1, -1.0, 0.0), 1e-12);
  EXPECT_NEAR(0.7449379339884389, reward(1.0, 2 * M_PI + 0.1, -1.0, 0.0), 1e-12);
  // The cart's velocity is not in the reward.
  EXPECT_DOUBLE_EQ(swingup.evaluate(CartPoleState(0.3, -4.0, -2.5, 7.0), 1, 2.0).reward,
                   swingup.evaluate(CartPoleState(0.3, 4.0, -2.5, 7.0), 1, 2.0).reward);
  EXPECT_NEAR(0.048598508479111575, swingup.evaluate(CartPoleState(0.3, 0.0, -2.5, 7.0), 1, 2.0).reward, 1e-12);
}

TEST(SuiteTask, BalanceScoresAsSwingupDoes)
{
  const CartPoleTask balance = taskOf(TaskKind::Balance);
  const CartPoleTask swingup = taskOf(TaskKind::Swingup);
  for (const CartPoleState& s : {CartPoleState(0.1, 0.0, 0.02, -0.3), CartPoleState(-1.7, 2.0, 2.0, 9.0)})
    EXPECT_EQ(swingup.evaluate(s, 5, 3.0).reward, balance.evaluate(s, 5, 3.0).reward);
}

TEST(SuiteTask, SparseRewardIsOneOnlyCentredAndUpright)
{
  const CartPoleTask sparse = taskOf(TaskKind::SwingupSparse);
  const auto reward = [&](double x, double theta) {
    return sparse.evaluate(CartPoleState(x, 1.0, theta, 3.0), 1, 10.0).reward;
  };
  EXPECT_EQ(1.0, reward(0.0, 0.0));
  // Both bounds inclusive: |x| <= 0.25, cos(theta) >= 0.995 (theta within acos(0.995) = 0.10004 rad).
  EXPECT_EQ(1.0, reward(0.25, 0.0));
  EXPECT_EQ(1.0, reward(-0.25, 0.0));
  EXPECT_EQ(0.0, reward(std::nextafter(0.25, 1.0), 0.0));
  EXPECT_EQ(1.0, reward(0.0, 0.1));
  EXPECT_EQ(1.0, reward(0.0, -0.1));
  EXPECT_EQ(0.0, reward(0.0, 0.1001));
  EXPECT_EQ(0.0, reward(0.0, M_PI));
  EXPECT_EQ(1.0, reward(0.1, -2 * M_PI + 0.05));
  // Control and velocities cost nothing here.
  EXPECT_EQ(1.0, sparse.evaluate(CartPoleState(0.0, 50.0, 0.0, 50.0), 1, -10.0).reward);
}

TEST(SuiteTask, EpisodesEndOnlyAfterTheirThousandSteps)
{
  for (const TaskKind kind : {TaskKind::Balance, TaskKind::Swingup, TaskKind::SwingupSparse})
  {
    const CartPoleTask task = taskOf(kind);
    // Far off the rail's middle and lying flat: CartPole-v1 would have ended long ago.
    const CartPoleState far(2.9, 0.0, M_PI / 2, 0.0);
    EXPECT_FALSE(task.isTerminal(far));
    EXPECT_FALSE(task.evaluate(far, 999, 0.0).done());
    const StepOutcome last = task.evaluate(far, 1000, 0.0);
    EXPECT_TRUE(last.truncated);
    EXPECT_FALSE(last.terminated);
    EXPECT_EQ(last.reward, last.score);
    EXPECT_EQ(1000.0, task.params().largestReturn());
  }
}

TEST(SuiteTask, ValidateRefusesCartPoleRewards)
{
  TaskParams params;
  params.kind = TaskKind::Swingup;
  params.max_episode_steps = kSuiteEpisodeSteps;
  EXPECT_EQ("", params.validate());
  params.reward = RewardScheme::Seed;
  EXPECT_NE(std::string::npos, params.validate().find("reward seed"));
}

TEST(SuiteTask, StartsAreTheSuitesDistributions)
{
  TaskParams params;
  params.kind = TaskKind::Swingup;
  CartPoleSimulation swingup(CartPoleParams(), 0.05, 7);
  swingup.setStart(params.start(0.05));
  params.kind = TaskKind::Balance;
  CartPoleSimulation balance(CartPoleParams(), 0.05, 7);
  balance.setStart(params.start(0.05));
  double theta_sum = 0.0;
  const int n = 2000;
  for (int i = 0; i < n; ++i)
  {
    // Swingup: every value 0.01 x normal, about theta = pi (hanging): within 6 standard deviations.
    const CartPoleState hanging = swingup.resetRandom();
    theta_sum += hanging[2];
    for (std::size_t d = 0; d < kStateDimensions; ++d)
      EXPECT_LT(std::fabs(hanging[d] - (d == 2 ? M_PI : 0.0)), 0.06) << d;
    // Balance: x uniform in +-0.1, theta uniform in +-0.034, velocities 0.01 x normal.
    const CartPoleState near_up = balance.resetRandom();
    EXPECT_LE(std::fabs(near_up[0]), 0.1);
    EXPECT_LE(std::fabs(near_up[2]), 0.034);
    EXPECT_LT(std::fabs(near_up[1]), 0.06);
    EXPECT_LT(std::fabs(near_up[3]), 0.06);
  }
  EXPECT_NEAR(M_PI, theta_sum / n, 0.001);
  // CartPole-v1 keeps its uniform starts in +-start_state_bound.
  const StartDistribution v1 = TaskParams().start(0.05);
  EXPECT_EQ(CartPoleState::Constant(0.05), v1.spread);
  EXPECT_EQ(CartPoleState::Zero(), v1.centre);
}

TEST(SuiteTask, FeaturesSeeThePoleOnTheCircle)
{
  FeatureParams bins;
  bins.discretiser.bins = {1, 1, 8, 1};
  bins.discretiser.lower[2] = -M_PI;
  bins.discretiser.upper[2] = M_PI;
  FeatureParams tiles = bins;
  tiles.kind = FeatureKind::Tiles;
  tiles.tiles = {1, 1, 8, 4};
  tiles.discretiser.lower[3] = -10.0;
  tiles.discretiser.upper[3] = 10.0;
  for (const FeatureParams& params : {bins, tiles})
  {
    const FeatureMap features(params, 5);
    ActiveRows once, turned, back;
    for (const double theta : {0.0, 0.3, -2.0, 3.0})
    {
      features.activeRows(CartPoleState(0.0, 0.0, theta, 1.5), once);
      features.activeRows(CartPoleState(0.0, 0.0, theta + 2 * M_PI, 1.5), turned);
      features.activeRows(CartPoleState(0.0, 0.0, theta - 6 * M_PI, 1.5), back);
      ASSERT_EQ(once.count, turned.count);
      for (unsigned i = 0; i < once.count; ++i)
      {
        EXPECT_EQ(once.rows[i], turned.rows[i]) << theta;
        EXPECT_EQ(once.rows[i], back.rows[i]) << theta;
      }
    }
  }
}

TEST(SuiteTask, TheConfigReadsTheKindAndWritesItOnlyWhenNotTheDefault)
{
  const TrainingConfig plain = configOf("{}");
  EXPECT_EQ(std::string::npos, trainingConfigText(plain).find("kind"));
  const TrainingConfig swingup = configOf("{physics: {tau: 0.01}, task: {kind: swingup}}");
  EXPECT_EQ(TaskKind::Swingup, swingup.task.kind);
  EXPECT_EQ(kSuiteEpisodeSteps, swingup.task.max_episode_steps);
  EXPECT_NE(std::string::npos, trainingConfigText(swingup).find("kind: swingup"));
  const TrainingConfig again = configOf(trainingConfigText(swingup));
  EXPECT_EQ(TaskKind::Swingup, again.task.kind);
  // The Suite's steps are 0.01 s, its episodes 1,000 of them, and nothing ends them on the angle.
  EXPECT_THROW(configOf("{task: {kind: swingup}}"), ConfigError);
  EXPECT_THROW(configOf("{physics: {tau: 0.01}, task: {kind: balance, max_episode_steps: 500}}"), ConfigError);
  EXPECT_THROW(configOf("{physics: {tau: 0.01}, task: {kind: balance, theta_threshold_deg: 12}}"), ConfigError);
  EXPECT_THROW(configOf("{task: {kind: swing}}"), ConfigError);
}

TEST(SuiteTask, TheShippedConfigsAreTheSuitesTasks)
{
  const std::pair<const char*, TaskKind> configs[] = {
      {"swingup.yaml", TaskKind::Swingup},
      {"swingup_sparse.yaml", TaskKind::SwingupSparse},
      {"dmc_balance.yaml", TaskKind::Balance},
  };
  for (const auto& [file, kind] : configs)
  {
    const TrainingConfig config = readTrainingConfig(*loadYamlParameters(std::string(CARTPOLE_CONFIG_DIR "/") + file));
    EXPECT_EQ(kind, config.task.kind) << file;
    EXPECT_EQ(kSuiteEpisodeSteps, config.task.max_episode_steps) << file;
    // The Suite's cart-pole: its gravity, step, integrator and rail, and an action set with a zero.
    EXPECT_EQ(9.81, config.physics.gravity) << file;
    EXPECT_EQ(Integrator::Rk4, config.physics.integrator) << file;
    EXPECT_EQ(1.8, config.physics.rail_limit) << file;
    EXPECT_GT(config.agent.actions.size(), 2u) << file;
    EXPECT_NE(config.agent.actions.end(), std::find(config.agent.actions.begin(), config.agent.actions.end(), 0.0))
        << file;
  }
}
