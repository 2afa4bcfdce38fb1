// DelayPredictor: on a robot that carries commands out a step or two late and is the model
// itself, the state predicted when a command is sent is the state the robot is in when that
// command acts, exactly.
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/common/random.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <gtest/gtest.h>

#include <deque>
#include <stdexcept>

using namespace cartpole_qlearning;

namespace
{
void expectSameState(const CartPoleState& expected, const CartPoleState& actual, const std::string& where)
{
  for (std::size_t d = 0; d < kStateDimensions; ++d)
    EXPECT_NEAR(expected[d], actual[d], 1e-12) << where << ", dimension " << d;
}
}  // namespace

TEST(DelayPredictor, ThePredictionIsTheStateWhenTheCommandActs)
{
  for (unsigned delay = 1; delay <= 3; ++delay)
  {
    CartPoleParams physics;
    PerturbationParams late;
    late.delay_steps = delay;
    late.delay_steps_max = delay;
    CartPoleSimulation robot(physics, 0.05, 7, late);
    DelayPredictor predictor(physics, delay);
    RandomStream commands(3, 1);
    for (int episode = 0; episode < 3; ++episode)
    {
      robot.resetRandom();
      predictor.begin(robot.observation());
      // The states predicted when the last `delay` commands were sent, oldest first: the command
      // sent at step k acts from the state of step k + delay.
      std::deque<CartPoleState> predictions;
      int compared = 0;
      for (int step = 0; step < 40; ++step)
      {
        if (predictions.size() == delay)
        {
          expectSameState(predictions.front(), robot.observation(),
                          "delay " + std::to_string(delay) + ", step " + std::to_string(step));
          predictions.pop_front();
          ++compared;
        }
        predictions.push_back(predictor.predict(robot.observation()));
        // Beyond the motor's 10 N now and then: both clamp.
        const double command = commands.uniform(-12.0, 12.0);
        predictor.sent(command);
        robot.step(command);
      }
      EXPECT_EQ(compared, 40 - static_cast<int>(delay));
    }
  }
}

TEST(DelayPredictor, NoDelayPredictsWhatIsObservedAndTooManyStepsAreRefused)
{
  DelayPredictor none(CartPoleParams(), 0);
  CartPoleState state;
  state << 0.1, -0.2, 0.03, 0.4;
  none.sent(10.0);
  EXPECT_EQ(none.predict(state), state);
  EXPECT_EQ(none.steps(), 0u);
  EXPECT_EQ(DelayPredictor(CartPoleParams(), kMaxPredictedDelaySteps).steps(), kMaxPredictedDelaySteps);
  EXPECT_THROW(DelayPredictor(CartPoleParams(), kMaxPredictedDelaySteps + 1), std::invalid_argument);
}

TEST(DelayPredictor, AnEpisodeBeginsWithZeroInFlight)
{
  const CartPoleParams physics;
  DelayPredictor predictor(physics, 1);
  CartPoleState state;
  state << 0.0, 0.0, 0.05, 0.0;
  predictor.sent(10.0);
  const CartPoleDynamics model(physics);
  expectSameState(model.step(state, 10.0), predictor.predict(state), "after a command");
  predictor.begin(state);
  expectSameState(model.step(state, 0.0), predictor.predict(state), "after begin");
}

// Not told the delay: it predicts for the observed state until the delay is found from the states,
// then for the state the command will meet, exactly as when told.
TEST(DelayPredictor, AFoundDelayPredictsAsAToldOne)
{
  const CartPoleParams physics;
  PerturbationParams late;
  late.delay_steps = late.delay_steps_max = 2;
  CartPoleSimulation robot(physics, 0.05, 5, late);
  DelayPredictor found(physics, kDelayFoundFromStates);
  DelayPredictor told(physics, 2);
  EXPECT_TRUE(found.finding());
  EXPECT_FALSE(told.finding());
  robot.resetRandom();
  found.begin(robot.observation());
  told.begin(robot.observation());
  EXPECT_EQ(0u, found.steps()) << "nothing found before a command";
  expectSameState(robot.observation(), found.predict(robot.observation()), "before the delay is found");
  for (int step = 0; step < 150; ++step)
  {
    const CartPoleState& s = robot.observation();
    const double effort = s[2] + 0.3 * s[3] + 0.05 * s[1] > 0.0 ? 10.0 : -10.0;
    found.sent(effort);
    told.sent(effort);
    robot.step(effort);
    found.observed(robot.observation());
    told.observed(robot.observation());
  }
  EXPECT_EQ(2u, found.steps());
  expectSameState(told.predict(robot.observation()), found.predict(robot.observation()), "once found");
}
