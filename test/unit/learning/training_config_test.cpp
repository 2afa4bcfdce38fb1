#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/cartpole_task.h"

#include <gtest/gtest.h>

#include <cstdlib>

using namespace cartpole_qlearning;

namespace
{
TrainingConfig parse(const std::string& yaml)
{
  const auto source = parseYamlParameters(yaml, "test.yaml");
  refuseUnknownSections(*source);
  return readTrainingConfig(*source);
}

// The message of the ConfigError that parsing throws, or "" when it does not throw.
std::string errorOf(const std::string& yaml)
{
  try
  {
    parse(yaml);
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, ShippedFileLoadsWithTheDocumentedDefaults)
{
  const auto source = loadYamlParameters(CARTPOLE_CONFIG_DIR "/cartpole.yaml");
  refuseUnknownSections(*source);
  const TrainingConfig config = readTrainingConfig(*source);
  // The file spells out the built-in defaults, so both must agree.
  const TrainingConfig defaults = parse("");
  EXPECT_EQ(defaults.physics.gravity, config.physics.gravity);
  EXPECT_EQ(defaults.physics.tau, config.physics.tau);
  EXPECT_EQ(defaults.physics.integrator, config.physics.integrator);
  EXPECT_EQ(defaults.start_state_bound, config.start_state_bound);
  EXPECT_EQ(defaults.task.max_episode_steps, config.task.max_episode_steps);
  EXPECT_EQ(defaults.task.reward, config.task.reward);
  EXPECT_EQ(defaults.agent.gamma, config.agent.gamma);
  EXPECT_EQ(defaults.agent.actions, config.agent.actions);
  EXPECT_TRUE(defaults.agent.discretiser == config.agent.discretiser);
  EXPECT_EQ(defaults.agent.epsilon.type, config.agent.epsilon.type);
  EXPECT_EQ(defaults.agent.epsilon.start, config.agent.epsilon.start);
  EXPECT_EQ(defaults.agent.epsilon.min, config.agent.epsilon.min);
  EXPECT_EQ(defaults.agent.epsilon.decay_episodes, config.agent.epsilon.decay_episodes);
  EXPECT_EQ(defaults.agent.epsilon.log_divisor, config.agent.epsilon.log_divisor);
  EXPECT_EQ(defaults.agent.alpha.type, config.agent.alpha.type);
  EXPECT_EQ(defaults.agent.alpha.min, config.agent.alpha.min);
  EXPECT_EQ(defaults.agent.alpha.log_divisor, config.agent.alpha.log_divisor);
  EXPECT_EQ(defaults.limits.max_episodes, config.limits.max_episodes);
  EXPECT_EQ(defaults.limits.suite_every, config.limits.suite_every);
  EXPECT_EQ(defaults.limits.best_every, config.limits.best_every);
  EXPECT_EQ(12u, config.agent.discretiser.bins[3]);
}

TEST(Config, ValuesOverrideDefaults)
{
  const TrainingConfig c = parse(
      "physics: {tau: 0.01, integrator: rk4}\n"
      "task: {reward: seed, max_episode_steps: 200}\n"
      "learning:\n  gamma: 0.9\n  bins: [1, 1, 3, 4]\n  epsilon: {schedule: exponential, decay_rate: 0.9}\n"
      "training: {max_episodes: 7, stop_when_solved: false, suite_every: 1, best_every: 10}\n");
  EXPECT_EQ(0.01, c.physics.tau);
  EXPECT_EQ(Integrator::Rk4, c.physics.integrator);
  EXPECT_EQ(RewardScheme::Seed, c.task.reward);
  EXPECT_EQ(200u, c.task.max_episode_steps);
  EXPECT_EQ(0.9, c.agent.gamma);
  EXPECT_EQ(3u, c.agent.discretiser.bins[2]);
  EXPECT_EQ(ScheduleType::Exponential, c.agent.epsilon.type);
  EXPECT_EQ(0.9, c.agent.epsilon.decay_rate);
  EXPECT_EQ(7u, c.limits.max_episodes);
  EXPECT_FALSE(c.limits.stop_when_solved);
  EXPECT_EQ(10u, c.limits.best_every);
  // Written with the table as read (the configuration a table carries).
  EXPECT_EQ(10u, parse(trainingConfigText(c)).limits.best_every);
}

TEST(Config, BadValuesNameTheKeyTheValueAndTheRange)
{
  EXPECT_NE(std::string::npos,
            errorOf("learning: {gamma: 1.5}").find("learning/gamma = 1.5 is not allowed (must be in [0, 1])"));
  EXPECT_NE(std::string::npos, errorOf("physics: {mass_pole: -1}").find("physics/mass_pole = -1"));
  // Too many bins: refused with the value given (checked before any conversion), and too many
  // states in all before anything is allocated.
  const std::string huge_bins = errorOf("learning: {bins: [10000000000, 1, 1, 1]}");
  EXPECT_NE(std::string::npos, huge_bins.find("1e+10")) << huge_bins;
  EXPECT_NE(std::string::npos, huge_bins.find("[1, 1000]")) << huge_bins;
  // A key that is not a plain name (found by test/fuzz/config_fuzzer.cpp: a YAML exception
  // escaped the reader).
  EXPECT_FALSE(errorOf("learning: {bins: [1, 1, 3, 4], ! ctions: [-1,10 00 ,]}\ntask: {reward: dees}\n").empty());
  EXPECT_FALSE(errorOf("learning: {[1, 2]: 3}").empty());
  const std::string many_states = errorOf("learning: {bins: [1000, 1000, 1000, 1000]}");
  EXPECT_NE(std::string::npos, many_states.find("1000000000000 states")) << many_states;
  EXPECT_NE(std::string::npos, errorOf("physics: {integrator: verlet}").find("physics/integrator = 'verlet'"));
  EXPECT_NE(std::string::npos, errorOf("task: {max_episode_steps: 0}").find("task/max_episode_steps = 0"));
  EXPECT_NE(std::string::npos, errorOf("learning: {bins: [1, 1, 6]}").find("learning/bins"));
  EXPECT_NE(std::string::npos, errorOf("learning: {bins: [1, 1, 6, 2.5]}").find("whole numbers"));
  EXPECT_NE(std::string::npos, errorOf("learning: {epsilon: {min: 3}}").find("learning/epsilon/min = 3"));
  EXPECT_NE(std::string::npos, errorOf("learning: {actions: [-20, 20]}").find("physics/force_mag"));
  EXPECT_NE(std::string::npos, errorOf("training: {max_episodes: 0}").find("training/max_episodes = 0"));
  EXPECT_NE(std::string::npos, errorOf("training: {best_every: -1}").find("training/best_every = -1"));
  // The best is looked for at evaluations: best_every names some of suite_every's episodes.
  EXPECT_NE(std::string::npos, errorOf("training: {suite_every: 2, best_every: 5}")
                                   .find("training/best_every = 5 is not allowed (0, or a multiple of "
                                         "training/suite_every (2)"));
  EXPECT_NE(std::string::npos, errorOf("training: {best_every: 10}").find("training/best_every = 10"));
  EXPECT_EQ("", errorOf("training: {suite_every: 5, best_every: 20}"));
  EXPECT_NE(std::string::npos, errorOf("training: {until: forever}").find("training/until = 'forever'"));
  EXPECT_NE(std::string::npos, errorOf("training: {until: suite_passes}").find("needs training/suite_every > 0"));
  EXPECT_NE(std::string::npos,
            errorOf("training: {until: suite_passes, suite_every: 5, suite: none}").find("needs training/suite_every"));
}

TEST(Config, TileCodingKeys)
{
  EXPECT_EQ(FeatureKind::Bins, parse("").agent.features);  // the default
  const TrainingConfig c = parse(
      "learning:\n  features: tiles\n  tilings: 4\n  tiles: [1, 2, 6, 12]\n"
      "  lower_bounds: [-2.4, -2.0, -0.2, -1.0]\n  upper_bounds: [2.4, 2.0, 0.2, 1.0]\n");
  EXPECT_EQ(FeatureKind::Tiles, c.agent.features);
  EXPECT_EQ(4u, c.agent.tilings);
  EXPECT_EQ(2u, c.agent.tiles[1]);
  EXPECT_EQ(-2.0, c.agent.featureParams().tileCoder().lower[1]);  // the bounds are the bins' keys
  EXPECT_EQ(1.0, c.agent.featureParams().tileCoder().upper[3]);

  const std::string kind = errorOf("learning: {features: tile}");
  EXPECT_NE(std::string::npos, kind.find("learning/features = 'tile' is not allowed (allowed: bins, tiles)")) << kind;
  const std::string tilings = errorOf("learning: {features: tiles, tilings: 0}");
  EXPECT_NE(std::string::npos, tilings.find("learning/tilings = 0 is not allowed (must be a whole number in [1, 64])"))
      << tilings;
  EXPECT_NE(std::string::npos, errorOf("learning: {tilings: 65}").find("learning/tilings = 65")) << tilings;
  EXPECT_NE(std::string::npos, errorOf("learning: {tiles: [1, 1, 6]}").find("learning/tiles")) << tilings;
  EXPECT_NE(std::string::npos, errorOf("learning: {tiles: [1, 1, 0, 6]}").find("learning/tiles = [1, 1, 0, 6]"));
  // Too many tiles in all: refused before anything is allocated, naming the key.
  const std::string many = errorOf("learning: {features: tiles, tilings: 64, tiles: [20, 20, 20, 20]}");
  EXPECT_NE(std::string::npos, many.find("learning/tiles give 12446784 tiles")) << many;
  // Bounds a used tile dimension needs, checked only when tiles are in use.
  const std::string bounds = "lower_bounds: [0, 0, 0, 1]\n  upper_bounds: [1, 1, 1, 1]\n  bins: [1, 1, 2, 1]\n";
  EXPECT_EQ("", errorOf("learning:\n  tiles: [1, 1, 1, 2]\n  " + bounds));
  const std::string tile_bounds = errorOf("learning:\n  features: tiles\n  tiles: [1, 1, 1, 2]\n  " + bounds);
  EXPECT_NE(std::string::npos, tile_bounds.find("learning/lower_bounds[3], upper_bounds[3] (theta_dot) = 1, 1"))
      << tile_bounds;
}

TEST(Config, WrongTypesAreRefused)
{
  EXPECT_NE(std::string::npos, errorOf("physics: {gravity: strong}").find("physics/gravity = 'strong'"));
  EXPECT_NE(std::string::npos, errorOf("physics: {gravity: [1, 2]}").find("physics/gravity"));
  EXPECT_NE(std::string::npos, errorOf("learning: {actions: 10}").find("learning/actions must be a list"));
  EXPECT_NE(std::string::npos, errorOf("training: {stop_when_solved: maybe}").find("training/stop_when_solved"));
}

TEST(Config, UnknownKeysAndSectionsAreRefused)
{
  const std::string typo = errorOf("learning: {gama: 0.9}");
  EXPECT_NE(std::string::npos, typo.find("unknown key learning/gama")) << typo;
  EXPECT_NE(std::string::npos, typo.find("gamma")) << typo;  // lists what is known
  EXPECT_NE(std::string::npos, errorOf("learnin: {gamma: 0.9}").find("unknown key learnin/gamma"));
  EXPECT_NE(std::string::npos, errorOf("learning: {epsilon: {mn: 0.1}}").find("learning/epsilon/mn"));
}

TEST(Config, InvalidYamlAndMissingFilesAreRefused)
{
  EXPECT_NE(std::string::npos, errorOf("physics: [unclosed").find("not valid YAML"));
  EXPECT_THROW(loadYamlParameters("/nonexistent/cartpole.yaml"), ConfigError);
}

namespace
{
TrainingConfig readFrom(const std::string& yaml, const std::string& folder)
{
  return readTrainingConfig(*parseYamlParameters(yaml, "test.yaml", folder));
}
}  // namespace

TEST(Config, TheEngineIsTheEquationsUnlessTheConfigNamesAModel)
{
  EXPECT_EQ("equations", parse("").engine.name);
  const TrainingConfig c = readFrom(
      "physics: {engine: mujoco, model: models/pole.xml, cart_joint: a, pole_joint: b, actuator: c, tau: 0.04}",
      "/configs");
  EXPECT_EQ("mujoco", c.engine.name);
  EXPECT_EQ("/configs/models/pole.xml", c.engine.model);  // relative to the config's folder
  EXPECT_EQ("a", c.engine.cart_joint);
  EXPECT_EQ("b", c.engine.pole_joint);
  EXPECT_EQ("c", c.engine.actuator);
  EXPECT_EQ("/abs/pole.xml", readFrom("physics: {engine: mujoco, model: /abs/pole.xml}", "/configs").engine.model);
  // The defaults are Gymnasium's InvertedPendulum's names.
  EXPECT_EQ("slider", EngineParams().cart_joint);
  EXPECT_EQ("hinge", EngineParams().pole_joint);
  EXPECT_EQ("slide", EngineParams().actuator);
}

TEST(Config, AModelPathTakesEnvironmentVariables)
{
  ::setenv("CARTPOLE_TEST_ASSETS", "/opt/assets", 1);
  EXPECT_EQ("/opt/assets/pendulum.xml",
            readFrom("physics: {engine: mujoco, model: \"${CARTPOLE_TEST_ASSETS}/pendulum.xml\"}", "/c").engine.model);
  ::unsetenv("CARTPOLE_TEST_ASSETS");
  const std::string unset = errorOf("physics: {engine: mujoco, model: \"${CARTPOLE_TEST_ASSETS}/pendulum.xml\"}");
  EXPECT_NE(std::string::npos, unset.find("physics/model = '${CARTPOLE_TEST_ASSETS}/pendulum.xml'")) << unset;
  EXPECT_NE(std::string::npos, unset.find("CARTPOLE_TEST_ASSETS is not set")) << unset;
}

TEST(Config, EngineKeysThatDoNotApplyAreRefused)
{
  EXPECT_NE(std::string::npos, errorOf("physics: {engine: ode}").find("physics/engine = 'ode' is not allowed"));
  EXPECT_NE(std::string::npos, errorOf("physics: {engine: mujoco}").find("physics/model = '' is not allowed"));
  const std::string mass = errorOf("physics: {engine: mujoco, model: m.xml, mass_pole: 0.2}");
  EXPECT_NE(std::string::npos, mass.find("physics/mass_pole is not allowed with physics/engine mujoco")) << mass;
  EXPECT_NE(std::string::npos,
            errorOf("physics: {engine: mujoco, model: m.xml, integrator: rk4}").find("physics/integrator"));
  const std::string joint = errorOf("physics: {cart_joint: slider}");
  EXPECT_NE(std::string::npos, joint.find("physics/cart_joint is not allowed with physics/engine equations")) << joint;
  const std::string length =
      errorOf("physics: {engine: mujoco, model: m.xml}\nperturbations: {half_length: [0.9, 1.1]}");
  EXPECT_NE(std::string::npos, length.find("perturbations/half_length is not allowed with physics/engine mujoco"))
      << length;
}

TEST(Config, TheAliveRewardIsInvertedPendulumsV5)
{
  TaskParams params;
  params.reward = rewardSchemeFromString("alive");
  const CartPoleTask task(params);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState::Zero(), 1, 0.0).reward);
  EXPECT_EQ(0.0, task.evaluate(CartPoleState(0.0, 0.0, 1.0, 0.0), 1, 0.0).reward);
  EXPECT_EQ("alive", toString(RewardScheme::Alive));
}

TEST(Config, TheCentredRewardCostsACartOffTheCentreAndTheFallMore)
{
  TaskParams params;
  params.reward = rewardSchemeFromString("centred");
  const CartPoleTask task(params);
  // At the centre a step costs nothing (sutton_barto's 0); half way to the end of the track a
  // quarter of kCentredCost, either side; at the very end kCentredCost; past it, the fall's -1.
  EXPECT_EQ(0.0, task.evaluate(CartPoleState::Zero(), 1, 0.0).reward);
  EXPECT_DOUBLE_EQ(-0.25 * kCentredCost, task.evaluate(CartPoleState(1.2, 0.0, 0.0, 0.0), 1, 0.0).reward);
  EXPECT_DOUBLE_EQ(-0.25 * kCentredCost, task.evaluate(CartPoleState(-1.2, 0.0, 0.0, 0.0), 1, 0.0).reward);
  EXPECT_DOUBLE_EQ(-kCentredCost, task.evaluate(CartPoleState(2.4, 0.0, 0.0, 0.0), 1, 0.0).reward);
  EXPECT_EQ(-1.0, task.evaluate(CartPoleState(2.5, 0.0, 0.0, 0.0), 1, 0.0).reward);
  EXPECT_EQ(-1.0, task.evaluate(CartPoleState(0.0, 0.0, 1.0, 0.0), 1, 0.0).reward);
  // Truncation is no fall: the step is worth what its state is.
  const StepOutcome last = task.evaluate(CartPoleState(1.2, 0.0, 0.0, 0.0), params.max_episode_steps, 0.0);
  EXPECT_TRUE(last.truncated);
  EXPECT_DOUBLE_EQ(-0.25 * kCentredCost, last.reward);
  EXPECT_EQ("centred", toString(RewardScheme::Centred));
  EXPECT_EQ(RewardScheme::Centred,
            readTrainingConfig(*parseYamlParameters("task: {reward: centred}", "t")).task.reward);
}

TEST(Config, ASolvedRewardAndAliveQuadraticsCostsAreReadAndWrittenOnlyWhenGiven)
{
  const TrainingConfig config =
      parse("task: {reward: alive_quadratic, x_cost: 0.5, x_dot_cost: 0.25, solved_reward: alive}");
  EXPECT_EQ(RewardScheme::AliveQuadratic, config.task.reward);
  ASSERT_TRUE(config.task.solved_reward.has_value());
  EXPECT_EQ(RewardScheme::Alive, *config.task.solved_reward);
  EXPECT_EQ(0.5, config.task.x_cost);
  EXPECT_EQ(0.25, config.task.x_dot_cost);
  const std::string text = trainingConfigText(config);
  EXPECT_NE(std::string::npos, text.find("solved_reward: alive")) << text;
  EXPECT_NE(std::string::npos, text.find("x_cost: 0.5")) << text;
  const TrainingConfig back = parse(text);
  EXPECT_EQ(text, trainingConfigText(back));
  // Absent: no key in the text (the tables of configs without them stay byte for byte).
  const std::string plain = trainingConfigText(parse("task: {reward: alive}"));
  EXPECT_EQ(std::string::npos, plain.find("solved_reward")) << plain;
  EXPECT_EQ(std::string::npos, plain.find("x_cost")) << plain;
  EXPECT_FALSE(parse("").task.solved_reward.has_value());
  const std::string bad = errorOf("task: {solved_reward: steps}");
  EXPECT_NE(std::string::npos, bad.find("task/solved_reward")) << bad;
  const std::string cost = errorOf("task: {reward: alive, x_cost: 1.0}");
  EXPECT_NE(std::string::npos, cost.find("only alive_quadratic reads them")) << cost;
}
