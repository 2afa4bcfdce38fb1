// DelayPredictor: on a robot that carries commands out a step or two late and is the model
// itself, the state predicted when a command is sent is the state the robot is in when that
// command acts, exactly.
#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/common/random.h"
#include "cartpole_qlearning/simulation/cartpole_simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <optional>
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

namespace
{
// A pole balanced by a linear bang-bang rule on `robot` (one step late) for `steps` steps, the
// predictor told the delay; returns the root mean square miss of the predictions over the last
// half, each against the true state when its command acted, and of the model's own prediction
// from the reading (what the predictor did before it fitted anything) in `model_miss`.
double balanceAndMeasure(CartPoleSimulation& robot, DelayPredictor& predictor, const CartPoleParams& physics, int steps,
                         double& model_miss)
{
  const CartPoleDynamics model(physics);
  robot.resetRandom();
  predictor.begin(robot.observation());
  double miss = 0.0;
  model_miss = 0.0;
  int counted = 0;
  std::optional<CartPoleState> predicted;
  std::optional<CartPoleState> model_predicted;
  double last_command = 0.0;
  for (int step = 0; step < steps; ++step)
  {
    if (predicted && step >= steps / 2)
    {
      miss += (*predicted - robot.state()).squaredNorm();
      model_miss += (*model_predicted - robot.state()).squaredNorm();
      ++counted;
    }
    const CartPoleState& seen = robot.observation();
    predicted = predictor.predict(seen);
    model_predicted = model.step(seen, model.clampForce(last_command));
    const CartPoleState& s = *predicted;
    const double command = 0.1 * s[0] + 0.5 * s[1] + 10.0 * s[2] + 1.5 * s[3] > 0.0 ? 10.0 : -10.0;
    predictor.sent(command);
    robot.step(command);
    predictor.observed(robot.observation());
    last_command = command;
  }
  model_miss = std::sqrt(model_miss / counted);
  return std::sqrt(miss / counted);
}
}  // namespace

// A robot whose motor is 20 % weaker and whose pole is 30 % longer than the model: the fit finds
// the weaker force in both velocities, and its predictions miss by much less than the model's.
TEST(DelayPredictor, TheFitFindsAWeakerMotorAndALongerPoleAndPredictsCloser)
{
  const CartPoleParams physics;
  PerturbationParams robot_is_not_the_model;
  robot_is_not_the_model.delay_steps = robot_is_not_the_model.delay_steps_max = 1;
  robot_is_not_the_model.motor = {0.8, 0.8};
  robot_is_not_the_model.half_length = {1.3, 1.3};
  CartPoleSimulation robot(physics, 0.05, 11, robot_is_not_the_model);
  DelayPredictor predictor(physics, 1);
  double model_miss = 0.0;
  const double miss = balanceAndMeasure(robot, predictor, physics, 600, model_miss);
  EXPECT_NEAR(predictor.fit()[0].force, 0.8, 0.08) << "the cart's velocity: the motor's force";
  EXPECT_LT(predictor.fit()[1].force, 0.7) << "the pole's velocity: the weaker force on a longer pole";
  EXPECT_LT(miss, 0.2 * model_miss) << "fitted " << miss << ", the model's " << model_miss;
}

// Noisy sensors on the model itself: the estimate, not the last reading, is advanced, and the
// predictions miss the true state by less than the model's prediction from the reading.
TEST(DelayPredictor, WithNoisySensorsThePredictionMissesLessThanOneFromTheReading)
{
  const CartPoleParams physics;
  PerturbationParams noisy;
  noisy.delay_steps = noisy.delay_steps_max = 1;
  noisy.noise_std = {0.01, 0.0, 0.0087, 0.0};
  noisy.noise_fraction = {0.0, 0.05, 0.0, 0.05};
  CartPoleSimulation robot(physics, 0.05, 12, noisy);
  DelayPredictor predictor(physics, 1);
  double model_miss = 0.0;
  const double miss = balanceAndMeasure(robot, predictor, physics, 600, model_miss);
  EXPECT_LT(miss, 0.9 * model_miss) << "fitted " << miss << ", the model's " << model_miss;
  for (const StepFit& fit : predictor.fit())
  {
    EXPECT_NEAR(fit.force, 1.0, 0.15);
    EXPECT_GE(fit.gravity, kFitLowest);
    EXPECT_LE(fit.gravity, kFitHighest);
  }
}

// On the model itself, without noise, the fit stays at the model and the predictions are exact;
// a robot told prompt gets the reading itself.
TEST(DelayPredictor, OnTheModelTheFitIsTheModelAndAPromptRobotGetsTheReading)
{
  const CartPoleParams physics;
  PerturbationParams late;
  late.delay_steps = late.delay_steps_max = 1;
  CartPoleSimulation robot(physics, 0.05, 13, late);
  DelayPredictor predictor(physics, 1);
  double model_miss = 0.0;
  EXPECT_LT(balanceAndMeasure(robot, predictor, physics, 300, model_miss), 1e-9);
  for (const StepFit& fit : predictor.fit())
  {
    EXPECT_NEAR(fit.gravity, 1.0, 1e-9);
    EXPECT_NEAR(fit.force, 1.0, 1e-9);
  }
  DelayPredictor prompt(physics, 0);
  CartPoleSimulation on_time(physics, 0.05, 13);
  double unused = 0.0;
  balanceAndMeasure(on_time, prompt, physics, 50, unused);
  const CartPoleState reading = on_time.observation();
  expectSameState(reading, prompt.predict(reading), "no delay");
}
