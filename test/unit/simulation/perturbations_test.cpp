// What a real cart-pole does (perturbations.h), in the core simulation that the sim node,
// train_headless and the robustness suite share.
#include "cartpole_qlearning/simulation/cartpole_simulation.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/learning/trace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace cartpole_qlearning;

namespace
{
// A command sequence that keeps the cart moving both ways.
double commandAt(int step)
{
  return (step / 3) % 2 == 0 ? 10.0 : -10.0;
}

std::string configError(const std::string& yaml)
{
  try
  {
    const auto source = parseYamlParameters(yaml, "test.yaml");
    refuseUnknownSections(*source);
    readTrainingConfig(*source);
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Perturbations, NoneLeavesTheIdealModelBitForBit)
{
  const CartPoleParams params;
  CartPoleSimulation sim(params, 0.05, 7);
  const CartPoleDynamics ideal(params);
  CartPoleState expected = sim.resetRandom();
  EXPECT_EQ(sim.observation(), sim.state());
  for (int k = 0; k < 200; ++k)
  {
    expected = ideal.step(expected, commandAt(k));
    sim.step(commandAt(k));
    ASSERT_EQ(sim.state(), expected) << "step " << k;
    ASSERT_EQ(sim.observation(), sim.state());
    ASSERT_EQ(sim.appliedForce(), commandAt(k));
  }
}

TEST(Perturbations, ADelayOfOneStepAppliesThePreviousCommand)
{
  const CartPoleParams params;
  PerturbationParams p;
  p.delay_steps = p.delay_steps_max = 1;
  CartPoleSimulation late(params, 0.05, 3, p);
  const CartPoleDynamics ideal(params);
  CartPoleState expected = late.resetRandom();
  double previous = 0.0;  // after a reset nothing is under way: zero acts first
  for (int k = 0; k < 50; ++k)
  {
    late.step(commandAt(k));
    EXPECT_EQ(late.appliedForce(), previous) << "step " << k;
    expected = ideal.step(expected, previous);
    ASSERT_EQ(late.state(), expected);
    previous = commandAt(k);
  }
  // A new episode empties the line: the last command of the old one never acts in the new one.
  late.resetRandom();
  late.step(5.0);
  EXPECT_EQ(late.appliedForce(), 0.0);
  late.step(-5.0);
  EXPECT_EQ(late.appliedForce(), 5.0);
}

TEST(Perturbations, ADelayRangeIsDrawnPerEpisode)
{
  PerturbationParams p;
  p.delay_steps = 0;
  p.delay_steps_max = 2;
  CartPoleSimulation sim(CartPoleParams(), 0.05, 8, p);
  int seen[3] = {0, 0, 0};
  for (int episode = 0; episode < 300; ++episode)
  {
    sim.resetRandom();
    ASSERT_LE(sim.delaySteps(), 2u);
    ++seen[sim.delaySteps()];
    // The command given now acts after exactly the drawn delay.
    for (unsigned k = 0; k < sim.delaySteps(); ++k)
    {
      sim.step(k == 0 ? 7.0 : 0.0);
      ASSERT_EQ(sim.appliedForce(), 0.0);
    }
    sim.step(sim.delaySteps() == 0 ? 7.0 : 0.0);
    ASSERT_EQ(sim.appliedForce(), 7.0);
  }
  for (const int count : seen)
    EXPECT_NEAR(count, 100, 35);
  const auto source = parseYamlParameters("perturbations: {delay_steps: [0, 1]}", "test.yaml");
  const PerturbationParams read = readPerturbations(*source);
  EXPECT_EQ(read.delay_steps, 0u);
  EXPECT_EQ(read.delay_steps_max, 1u);
}

TEST(Perturbations, ThreeStepsLateThenInOrder)
{
  ActuationDelay delay(3);
  EXPECT_EQ(delay.apply(1.0), 0.0);
  EXPECT_EQ(delay.apply(2.0), 0.0);
  EXPECT_EQ(delay.apply(3.0), 0.0);
  EXPECT_EQ(delay.apply(4.0), 1.0);
  EXPECT_EQ(delay.apply(5.0), 2.0);
  delay.reset();
  EXPECT_EQ(delay.apply(6.0), 0.0);
}

TEST(Perturbations, NoiseLeavesTheTrueStateAloneAndHasTheConfiguredSpread)
{
  const CartPoleParams params;
  PerturbationParams p;
  p.noise_std = {0.01, 0.0, 0.0087, 0.0};
  p.noise_fraction = {0.0, 0.05, 0.0, 0.0};
  CartPoleSimulation clean(params, 0.05, 11);
  CartPoleSimulation noisy(params, 0.05, 11, p);
  ASSERT_EQ(clean.resetRandom(), noisy.resetRandom());
  double sum_sq_x = 0.0;
  double sum_sq_theta = 0.0;
  double sum_sq_rel_x_dot = 0.0;
  int moving = 0;
  const int steps = 20000;
  for (int k = 0; k < steps; ++k)
  {
    // Keep the true state bounded: a fresh episode whenever the pole is far off.
    if (std::fabs(clean.state()[2]) > 0.5 || std::fabs(clean.state()[0]) > 2.0)
    {
      clean.resetRandom();
      noisy.resetRandom();
    }
    clean.step(commandAt(k));
    noisy.step(commandAt(k));
    ASSERT_EQ(clean.state(), noisy.state()) << "noise must not reach the physics (step " << k << ")";
    const CartPoleState error = noisy.observation() - noisy.state();
    EXPECT_EQ(error[3], 0.0);  // theta_dot: not noisy
    sum_sq_x += error[0] * error[0];
    sum_sq_theta += error[2] * error[2];
    if (std::fabs(noisy.state()[1]) > 1e-3)
    {
      sum_sq_rel_x_dot += std::pow(error[1] / std::fabs(noisy.state()[1]), 2);
      ++moving;
    }
  }
  // 20,000 draws: the measured spread is within a few percent of the configured one.
  EXPECT_NEAR(std::sqrt(sum_sq_x / steps), 0.01, 0.0005);
  EXPECT_NEAR(std::sqrt(sum_sq_theta / steps), 0.0087, 0.0005);
  ASSERT_GT(moving, steps / 2);
  EXPECT_NEAR(std::sqrt(sum_sq_rel_x_dot / moving), 0.05, 0.003);
}

TEST(Perturbations, PhysicsIsDrawnPerEpisodeWithinItsRangesAndReproducibleBySeed)
{
  const CartPoleParams params;
  PerturbationParams p;
  p.mass_cart = {0.7, 1.3};
  p.mass_pole = {0.7, 1.3};
  p.half_length = {0.7, 1.3};
  p.motor = {0.8, 1.0};
  CartPoleSimulation a(params, 0.05, 5, p);
  CartPoleSimulation b(params, 0.05, 5, p);
  CartPoleSimulation nominal(params, 0.05, 5);
  std::vector<double> carts;
  for (int episode = 0; episode < 200; ++episode)
  {
    // The start states are those of the ideal model with the same seed.
    ASSERT_EQ(a.resetRandom(), nominal.resetRandom());
    b.resetRandom();
    const CartPoleParams& drawn = a.dynamics().params();
    EXPECT_EQ(drawn.mass_cart, b.dynamics().params().mass_cart);
    EXPECT_EQ(drawn.half_length, b.dynamics().params().half_length);
    EXPECT_EQ(a.motorFactor(), b.motorFactor());
    EXPECT_GE(drawn.mass_cart, 0.7);
    EXPECT_LE(drawn.mass_cart, 1.3);
    EXPECT_GE(drawn.mass_pole, 0.07);
    EXPECT_LE(drawn.mass_pole, 0.13);
    EXPECT_GE(drawn.half_length, 0.35);
    EXPECT_LE(drawn.half_length, 0.65);
    EXPECT_GE(a.motorFactor(), 0.8);
    EXPECT_LE(a.motorFactor(), 1.0);
    EXPECT_EQ(drawn.force_mag, params.force_mag);  // the drive's limit stays; the motor gives less of it
    carts.push_back(drawn.mass_cart);
  }
  // Drawn afresh each episode, over the whole range.
  EXPECT_LT(*std::min_element(carts.begin(), carts.end()), 0.75);
  EXPECT_GT(*std::max_element(carts.begin(), carts.end()), 1.25);
  // Another seed draws other physics.
  CartPoleSimulation c(params, 0.05, 6, p);
  c.resetRandom();
  EXPECT_NE(c.dynamics().params().mass_cart, carts.front());
}

TEST(Perturbations, AWeakerMotorScalesTheClampedCommand)
{
  PerturbationParams p;
  p.motor = {0.8, 0.8};
  CartPoleSimulation weak(CartPoleParams(), 0.05, 1, p);
  weak.resetRandom();
  weak.step(10.0);
  EXPECT_DOUBLE_EQ(weak.appliedForce(), 8.0);
  weak.step(-25.0);  // clamped to the drive's 10 N first
  EXPECT_DOUBLE_EQ(weak.appliedForce(), -8.0);
}

TEST(Perturbations, PushesComeAtTheirRateBothWaysWithTheirForce)
{
  PerturbationParams p;
  p.push_probability = 0.1;
  p.push_force = 2.0;
  CartPoleSimulation pushed(CartPoleParams(), 0.05, 9, p);
  CartPoleSimulation calm(CartPoleParams(), 0.05, 9);
  ASSERT_EQ(pushed.resetRandom(), calm.resetRandom());
  int left = 0;
  int right = 0;
  const int steps = 10000;
  for (int k = 0; k < steps; ++k)
  {
    pushed.step(0.0);
    if (pushed.lastPush() != 0.0)
    {
      ASSERT_EQ(std::fabs(pushed.lastPush()), 2.0);
      EXPECT_EQ(pushed.appliedForce(), pushed.lastPush());
      (pushed.lastPush() < 0.0 ? left : right) += 1;
    }
    if (k % 100 == 99)
      pushed.resetRandom();
  }
  EXPECT_NEAR(left + right, 0.1 * steps, 120);  // about 4 standard deviations
  EXPECT_NEAR(left, right, 150);
}

TEST(Perturbations, FrictionSlowsTheCartAndThePole)
{
  const CartPoleDynamics without{CartPoleParams()};
  CartPoleParams cart_only;
  cart_only.cart_friction = 0.5;
  const CartPoleDynamics cart(cart_only);
  // The cart moving right is held back, moving left too; at rest it feels none (sgn(0) = 0).
  const CartPoleState right(0.0, 1.0, 0.0, 0.0);
  EXPECT_LT(cart.derivative(right, 0.0)[1], without.derivative(right, 0.0)[1]);
  const CartPoleState left(0.0, -1.0, 0.0, 0.0);
  EXPECT_GT(cart.derivative(left, 0.0)[1], without.derivative(left, 0.0)[1]);
  const CartPoleState still(0.0, 0.0, 0.1, 0.0);
  EXPECT_EQ(cart.derivative(still, 0.0), without.derivative(still, 0.0));

  CartPoleParams pole_only;
  pole_only.pole_friction = 0.01;
  const CartPoleDynamics pole(pole_only);
  // The pole turning either way is slowed by its hinge.
  const CartPoleState turning(0.0, 0.0, 0.0, 1.0);
  EXPECT_LT(pole.derivative(turning, 0.0)[3], without.derivative(turning, 0.0)[3]);
  const CartPoleState turning_back(0.0, 0.0, 0.0, -1.0);
  EXPECT_GT(pole.derivative(turning_back, 0.0)[3], without.derivative(turning_back, 0.0)[3]);
  // Barto, Sutton and Anderson's theta'' with the hinge term: -mu_p theta_dot / (m l) over the
  // same denominator.
  const double denominator = 0.5 * (4.0 / 3.0 - 0.1 / 1.1);
  EXPECT_NEAR(pole.derivative(turning, 0.0)[3] - without.derivative(turning, 0.0)[3], -0.01 / (0.1 * 0.5) / denominator,
              1e-12);
}

TEST(Perturbations, ReadFromTheirSectionAndRefusedWhenBad)
{
  const auto source = parseYamlParameters(
      "physics: {cart_friction: 0.0005, pole_friction: 0.000002}\n"
      "perturbations:\n"
      "  delay_steps: 1\n"
      "  noise_std: [0.01, 0, 0.0087, 0]\n"
      "  noise_fraction: [0, 0.05, 0, 0.05]\n"
      "  mass_cart: [0.7, 1.3]\n"
      "  motor: [0.8, 1.0]\n"
      "  push_probability: 0.02\n"
      "  push_force: 2.0\n",
      "test.yaml");
  refuseUnknownSections(*source);
  const TrainingConfig config = readTrainingConfig(*source);
  EXPECT_EQ(config.physics.cart_friction, 0.0005);
  EXPECT_EQ(config.physics.pole_friction, 0.000002);
  EXPECT_EQ(config.perturbations.delay_steps, 1u);
  EXPECT_EQ(config.perturbations.delay_steps_max, 1u);
  EXPECT_EQ(config.perturbations.noise_std[2], 0.0087);
  EXPECT_EQ(config.perturbations.noise_fraction[3], 0.05);
  EXPECT_EQ(config.perturbations.mass_cart.low, 0.7);
  EXPECT_EQ(config.perturbations.mass_cart.high, 1.3);
  EXPECT_FALSE(config.perturbations.mass_pole.varies());
  EXPECT_EQ(config.perturbations.motor.low, 0.8);
  EXPECT_EQ(config.perturbations.push_force, 2.0);
  EXPECT_TRUE(config.perturbations.any());

  EXPECT_NE(configError("perturbations: {delay_steps: -1}").find("perturbations/delay_steps = -1"), std::string::npos);
  EXPECT_NE(configError("perturbations: {delay_steps: [2, 1]}").find("perturbations/delay_steps = [2, 1]"),
            std::string::npos);
  EXPECT_NE(configError("perturbations: {delay_steps: fast}").find("delay_steps"), std::string::npos);
  EXPECT_NE(configError("perturbations: {mass_cart: [1.3, 0.7]}").find("mass_cart/high = 0.7"), std::string::npos);
  EXPECT_NE(configError("perturbations: {mass_cart: [1.0]}").find("[low, high]"), std::string::npos);
  EXPECT_NE(configError("perturbations: {push_probability: 2}").find("push_probability = 2"), std::string::npos);
  EXPECT_NE(configError("perturbations: {noise_std: [0, -1, 0, 0]}").find("noise_std[x_dot] = -1"), std::string::npos);
  EXPECT_NE(configError("perturbations: {delay: 1}").find("unknown key perturbations/delay"), std::string::npos);
  EXPECT_NE(configError("physics: {cart_friction: -0.1}").find("cart_friction = -0.1"), std::string::npos);
}

TEST(Perturbations, HeadlessTrainingIsReproducibleAndTheLearnerSeesTheNoisyState)
{
  TrainingConfig config;
  config.limits.max_episodes = 30;
  config.perturbations.delay_steps = config.perturbations.delay_steps_max = 1;
  config.perturbations.noise_std = {0.01, 0.0, 0.0087, 0.0};
  config.perturbations.push_probability = 0.02;
  config.perturbations.push_force = 2.0;
  HeadlessTrainer a(config, 4);
  HeadlessTrainer b(config, 4);
  const TrainingResult ra = a.run();
  const TrainingResult rb = b.run();
  EXPECT_EQ(ra.steps, rb.steps);
  EXPECT_EQ(a.session().table().values(), b.session().table().values());
  // The same seed without perturbations learns another table.
  TrainingConfig ideal = config;
  ideal.perturbations = PerturbationParams();
  HeadlessTrainer c(ideal, 4);
  c.run();
  EXPECT_NE(a.session().table().values(), c.session().table().values());
}

TEST(PreviousAction, EachPreviousActionHasItsOwnBlockOfRows)
{
  FeatureParams f;
  f.previous_action = true;
  const FeatureMap map(f, 2);
  ASSERT_EQ(map.rowCount(), 72u * 3u);
  const CartPoleState s(0.0, 0.0, 0.01, 0.1);
  ActiveRows none;
  ActiveRows after_left;
  ActiveRows after_right;
  map.activeRows(s, none, 0);
  map.activeRows(s, after_left, 1);
  map.activeRows(s, after_right, 2);
  EXPECT_LT(none.rows[0], 72u);
  EXPECT_EQ(after_left.rows[0], none.rows[0] + 72u);
  EXPECT_EQ(after_right.rows[0], none.rows[0] + 144u);
  // Off: the previous action changes nothing.
  const FeatureMap plain(FeatureParams(), 2);
  ActiveRows a;
  ActiveRows b;
  plain.activeRows(s, a, 0);
  plain.activeRows(s, b, 2);
  EXPECT_EQ(a.rows[0], b.rows[0]);
  // Tiles: every tiling's tile moves by the same block.
  FeatureParams t;
  t.kind = FeatureKind::Tiles;
  t.tilings = 4;
  t.previous_action = true;
  const FeatureMap tiles(t, 2);
  ActiveRows t0;
  ActiveRows t2;
  tiles.activeRows(s, t0, 0);
  tiles.activeRows(s, t2, 2);
  ASSERT_EQ(t0.count, 4u);
  for (unsigned i = 0; i < 4; ++i)
    EXPECT_EQ(t2.rows[i], t0.rows[i] + 2 * tiles.rowCount() / 3);
}

TEST(PreviousAction, TheSessionShowsTheLearnerTheActionItTookLast)
{
  AgentParams agent;
  agent.previous_action = true;
  TrainingSession session(TaskParams(), agent, 3);
  std::vector<std::size_t> states;
  std::vector<std::size_t> actions;
  session.setTrace([&](std::size_t, const TraceStep& step) {
    states.push_back(step.state);
    actions.push_back(step.action);
  });
  CartPoleSimulation sim(CartPoleParams(), 0.05, 3);
  double effort = session.beginEpisode(sim.resetRandom());
  for (int k = 0; k < 20; ++k)
  {
    const Decision d = session.observe(sim.step(effort));
    if (d.episode_over)
      break;
    effort = d.effort;
  }
  ASSERT_GT(states.size(), 3u);
  EXPECT_LT(states[0], 72u);  // the first state: no action before it
  for (std::size_t k = 1; k < states.size(); ++k)
    EXPECT_EQ(states[k] / 72u, actions[k - 1] + 1) << "step " << k;
}

TEST(PreviousAction, WithADelayedMotorTheLearnerThatSeesItLearnsToBalance)
{
  // The command acts one step late: the state alone is not enough to choose by, the state and
  // the action still under way are.
  TrainingConfig config;
  config.perturbations.delay_steps = config.perturbations.delay_steps_max = 1;
  config.limits.max_episodes = 2000;
  config.limits.stop_when_solved = false;
  const auto mean_return = [&](bool previous_action) {
    TrainingConfig c = config;
    c.agent.previous_action = previous_action;
    HeadlessTrainer trainer(c, 0);
    double last_500 = 0.0;
    trainer.run([&](const EpisodeSummary& s) {
      if (s.episode > 1500)
        last_500 += s.episode_return;
    });
    return last_500 / 500.0;
  };
  const double blind = mean_return(false);
  const double seeing = mean_return(true);
  EXPECT_LT(blind, 150.0);
  EXPECT_GT(seeing, 250.0);
}

TEST(Perturbations, DescribesWhatIsOnForTheSimsLog)
{
  PerturbationParams p;
  EXPECT_EQ("none", describePerturbations(p, 0.02));
  p.delay_steps = p.delay_steps_max = 1;
  p.noise_std = {0.01, 0.0, 0.0087, 0.0};
  p.motor = {0.8, 0.8};
  p.push_probability = 0.2;
  p.push_force = 2.0;
  EXPECT_EQ(
      "delay 1 step (0.02 s), noise_std [0.01, 0, 0.0087, 0] + noise_fraction [0, 0, 0, 0], motor x[0.8, 0.8], "
      "pushes of 2 N on 0.2 of the steps",
      describePerturbations(p, 0.02));
  p = PerturbationParams();
  p.delay_steps = 1;
  p.delay_steps_max = 3;
  p.mass_cart = {0.7, 1.3};
  EXPECT_EQ("delay 1-3 steps (0.01-0.03 s), mass_cart x[0.7, 1.3]", describePerturbations(p, 0.01));
}
