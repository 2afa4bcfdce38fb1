// DelayEstimator: a robot's delay found from its states, on robots that are not the model (the
// robustness suite's perturbations: noisy sensors, masses and length within 30 %, a weaker motor,
// pushes), driven as a balancing table drives them (a bang-bang policy on the observed state).
#include "cartpole_qlearning/learning/delay_estimator.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <gtest/gtest.h>

#include <optional>

using namespace cartpole_qlearning;

namespace
{
// The suite's all_at_once case without its delay (given per test).
PerturbationParams hostileRobot(unsigned delay)
{
  PerturbationParams p;
  p.delay_steps = delay;
  p.delay_steps_max = delay;
  p.noise_std = {0.01, 0.0, 0.0087, 0.0};
  p.noise_fraction = {0.0, 0.05, 0.0, 0.05};
  p.mass_cart = {0.7, 1.3};
  p.mass_pole = {0.7, 1.3};
  p.half_length = {0.7, 1.3};
  p.motor = {0.8, 0.8};
  p.push_probability = 0.2;
  p.push_force = 2.0;
  return p;
}

PerturbationParams promptRobot(unsigned delay)
{
  PerturbationParams p;
  p.delay_steps = delay;
  p.delay_steps_max = delay;
  return p;
}

// Full force toward what keeps the pole up (a balancing table's kind of commands).
double bangBang(const CartPoleState& s)
{
  return s[2] + 0.3 * s[3] + 0.01 * s[0] + 0.05 * s[1] > 0.0 ? 10.0 : -10.0;
}

struct Found
{
  std::optional<unsigned> estimate;
  int first_step = -1;  // when the estimate first was the robot's delay
  bool ever_wrong = false;
};

// Episodes of up to `steps` on the robot, the estimator told each start, state and command.
Found drive(const PerturbationParams& robot_params, std::uint64_t seed, int episodes, int steps)
{
  const CartPoleParams model;
  CartPoleSimulation robot(model, 0.05, seed, robot_params);
  DelayEstimator estimator(model);
  Found found;
  int step_count = 0;
  for (int episode = 0; episode < episodes; ++episode)
  {
    robot.resetRandom();
    estimator.begin(robot.observation());
    for (int step = 0; step < steps; ++step, ++step_count)
    {
      const double effort = bangBang(robot.observation());
      estimator.sent(effort);
      robot.step(effort);
      estimator.observed(robot.observation());
      if (estimator.estimate() && *estimator.estimate() != robot_params.delay_steps)
        found.ever_wrong = true;
      if (estimator.estimate() == robot_params.delay_steps && found.first_step < 0)
        found.first_step = step_count;
      if (std::abs(robot.state()[2]) > 0.5 || std::abs(robot.state()[0]) > 2.4)
        break;  // fell: the next episode
    }
  }
  found.estimate = estimator.estimate();
  return found;
}
}  // namespace

TEST(DelayEstimator, ThePromptModelItselfIsFoundPromptAndLateOnesLate)
{
  for (unsigned delay = 0; delay <= kLargestFoundDelay; ++delay)
  {
    const Found found = drive(promptRobot(delay), 11, 3, 300);
    ASSERT_TRUE(found.estimate.has_value()) << "delay " << delay;
    EXPECT_EQ(delay, *found.estimate);
    EXPECT_FALSE(found.ever_wrong) << "delay " << delay;
    EXPECT_LE(found.first_step, 60) << "delay " << delay;
  }
}

// The suite's hostile robot: never a wrong estimate, the right one within a few seconds of robot time.
TEST(DelayEstimator, AHostileRobotsDelayIsFoundAndNeverMistaken)
{
  for (unsigned delay = 0; delay <= 2; ++delay)
    for (std::uint64_t seed = 0; seed < 10; ++seed)
    {
      const Found found = drive(hostileRobot(delay), seed, 5, 500);
      ASSERT_TRUE(found.estimate.has_value()) << "delay " << delay << ", seed " << seed;
      EXPECT_EQ(delay, *found.estimate) << "seed " << seed;
      EXPECT_FALSE(found.ever_wrong) << "delay " << delay << ", seed " << seed;
      EXPECT_LE(found.first_step, 250) << "delay " << delay << ", seed " << seed;
    }
}

// Commands that never change tell the hypotheses apart never: no estimate rather than a guess.
TEST(DelayEstimator, NoEstimateWithoutCommandsThatTellTheDelaysApart)
{
  const CartPoleParams model;
  CartPoleSimulation robot(model, 0.05, 3, promptRobot(1));
  DelayEstimator estimator(model);
  estimator.begin(robot.observation());
  for (int step = 0; step < 200; ++step)
  {
    estimator.sent(0.0);
    robot.step(0.0);
    estimator.observed(robot.observation());
  }
  EXPECT_FALSE(estimator.estimate().has_value());
}
