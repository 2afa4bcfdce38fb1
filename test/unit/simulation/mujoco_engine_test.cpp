// The MuJoCo engine (mujoco_engine.h) behind CartPoleSimulation: signs, gear and clamp, frame
// skip, starts, each perturbation, each load error. Built when MuJoCo is found (mujoco_tests).
#include "cartpole_qlearning/simulation/mujoco_engine.h"
#include "cartpole_qlearning/simulation/physics_engines.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/application/headless_trainer.h"

#include <mujoco/mujoco.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

using namespace cartpole_qlearning;

namespace
{
const std::string kModel = CARTPOLE_SOURCE_DIR "/mjcf/cartpole.xml";

EngineParams projectModel()
{
  EngineParams params;
  params.name = "mujoco";
  params.model = kModel;
  params.cart_joint = "cart_joint";
  params.pole_joint = "pole_joint";
  params.actuator = "cart_motor";
  return params;
}

std::string readText(const std::string& path)
{
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The project's model with `from` replaced by `to`, written to a file of the test's own.
std::string modelWith(const std::string& from, const std::string& to, const std::string& name)
{
  std::string text = readText(kModel);
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos)
    text.replace(at, from.size(), to);
  const std::string path = ::testing::TempDir() + "/" + name + ".xml";
  std::ofstream(path) << text;
  return path;
}

// The EngineError's message when making the engine, or "" when it is made.
std::string loadError(const EngineParams& params, double tau = 0.02)
{
  try
  {
    MujocoEngine engine(params, tau);
  }
  catch (const EngineError& e)
  {
    return e.what();
  }
  return "";
}

TEST(MujocoEngine, TheProjectsModelLoadsWithItsGearFrameSkipAndSign)
{
  ASSERT_TRUE(mujocoAvailable());
  const MujocoEngine engine(projectModel(), 0.02);
  EXPECT_EQ(2, engine.frameSkip());  // timestep 0.01
  EXPECT_DOUBLE_EQ(10.0, engine.gear());
  EXPECT_DOUBLE_EQ(10.0, engine.forceLimit());
  EXPECT_EQ(1.0, engine.thetaSign());
  EXPECT_EQ(CartPoleState::Zero(), engine.state());
  EXPECT_DOUBLE_EQ(1.0, engine.model().body_mass[mj_name2id(&engine.model(), mjOBJ_BODY, "cart")]);
  EXPECT_DOUBLE_EQ(0.1, engine.model().body_mass[mj_name2id(&engine.model(), mjOBJ_BODY, "pole")]);
}

TEST(MujocoEngine, SignsFollowTheConvention)
{
  MujocoEngine engine(projectModel(), 0.02);
  // A push toward +x moves the cart toward +x and leaves the pole behind (leaning toward -x).
  engine.setState(CartPoleState::Zero());
  engine.step(10.0, 0.0);
  EXPECT_GT(engine.state()[1], 0.0);
  EXPECT_GT(engine.state()[0], 0.0);
  EXPECT_LT(engine.state()[3], 0.0);
  // A pole leaning toward +x falls further that way; the cart recoils toward -x.
  engine.setState(CartPoleState(0.0, 0.0, 0.1, 0.0));
  for (int i = 0; i < 5; ++i)
    engine.step(0.0, 0.0);
  EXPECT_GT(engine.state()[2], 0.1);
  EXPECT_GT(engine.state()[3], 0.0);
  EXPECT_LT(engine.state()[1], 0.0);
}

TEST(MujocoEngine, AHingeTurnedTheOtherWayGivesTheSameStates)
{
  EngineParams flipped = projectModel();
  flipped.model = modelWith("type=\"hinge\" axis=\"0 1 0\"", "type=\"hinge\" axis=\"0 -1 0\"", "flipped_hinge");
  MujocoEngine turned(flipped, 0.02);
  MujocoEngine plain(projectModel(), 0.02);
  EXPECT_EQ(-1.0, turned.thetaSign());
  const CartPoleState start(0.01, -0.02, 0.03, -0.04);
  turned.setState(start);
  plain.setState(start);
  EXPECT_NEAR(-0.03, turned.data().qpos[1], 1e-15);
  for (int i = 0; i < 20; ++i)
  {
    turned.step(i % 2 ? 7.0 : -3.0, 0.0);
    plain.step(i % 2 ? 7.0 : -3.0, 0.0);
    EXPECT_TRUE(turned.state().isApprox(plain.state(), 1e-12))
        << i << ": " << turned.state().transpose() << " vs " << plain.state().transpose();
  }
}

TEST(MujocoEngine, EffortIsCtrlTimesGearClampedToCtrlRangeAndCounted)
{
  MujocoEngine engine(projectModel(), 0.02);
  EXPECT_DOUBLE_EQ(5.0, engine.step(5.0, 0.0));
  EXPECT_DOUBLE_EQ(0.5, engine.data().ctrl[0]);
  EXPECT_EQ(0u, engine.clamps());
  EXPECT_DOUBLE_EQ(10.0, engine.step(25.0, 0.0));
  EXPECT_DOUBLE_EQ(1.0, engine.data().ctrl[0]);
  EXPECT_DOUBLE_EQ(-10.0, engine.step(-11.0, 0.0));
  EXPECT_DOUBLE_EQ(-1.0, engine.data().ctrl[0]);
  EXPECT_EQ(2u, engine.clamps());
  EXPECT_DOUBLE_EQ(-10.0, engine.step(-10.0, 0.0));
  EXPECT_EQ(2u, engine.clamps());
}

TEST(MujocoEngine, ATauIsAWholeNumberOfTimestepsMjStepsEach)
{
  MujocoEngine engine(projectModel(), 0.05);
  EXPECT_EQ(5, engine.frameSkip());
  EXPECT_DOUBLE_EQ(0.05, engine.tau());
  // The same as five mj_steps by hand.
  mjModel* model = mj_loadXML(kModel.c_str(), nullptr, nullptr, 0);
  ASSERT_NE(model, nullptr);
  mjData* data = mj_makeData(model);
  engine.setState(CartPoleState(0.0, 0.0, 0.05, 0.0));
  data->qpos[1] = 0.05;
  mj_forward(model, data);
  for (int s = 0; s < 3; ++s)
  {
    engine.step(4.0, 0.0);
    data->ctrl[0] = 0.4;
    for (int i = 0; i < 5; ++i)
      mj_step(model, data);
    EXPECT_EQ(data->time, engine.data().time);
    EXPECT_EQ(CartPoleState(data->qpos[0], data->qvel[0], data->qpos[1], data->qvel[1]), engine.state());
  }
  mj_deleteData(data);
  mj_deleteModel(model);
}

TEST(MujocoEngine, StartsAreTheSimulationsDrawsAfterAReset)
{
  CartPoleSimulation mujoco = makeSimulation(CartPoleParams(), projectModel(), 0.05, 17);
  CartPoleSimulation equations(CartPoleParams(), 0.05, 17);
  const auto& engine = dynamic_cast<const MujocoEngine&>(mujoco.engine());
  for (int episode = 0; episode < 5; ++episode)
  {
    const CartPoleState start = mujoco.resetRandom();
    EXPECT_EQ(equations.resetRandom(), start);  // the same stream, the same draws
    EXPECT_LE(start.cwiseAbs().maxCoeff(), 0.05);
    EXPECT_EQ(0.0, engine.data().time);  // mj_resetData
    EXPECT_EQ(start[0], engine.data().qpos[0]);
    EXPECT_EQ(start[1], engine.data().qvel[0]);
    EXPECT_EQ(start[2], engine.data().qpos[1]);
    EXPECT_EQ(start[3], engine.data().qvel[1]);
    for (int i = 0; i < 10; ++i)
      mujoco.step(10.0);
  }
  // A copy goes on as the original does.
  CartPoleSimulation copy = mujoco;
  EXPECT_EQ(mujoco.step(3.0), copy.step(3.0));
}

TEST(MujocoEngine, ADelayedCommandActsLater)
{
  PerturbationParams late;
  late.delay_steps = late.delay_steps_max = 1;
  CartPoleSimulation sim = makeSimulation(CartPoleParams(), projectModel(), 0.0, 3, late);
  sim.resetRandom();
  sim.step(10.0);
  EXPECT_EQ(0.0, sim.appliedForce());
  EXPECT_EQ(CartPoleState::Zero(), sim.state());  // upright at rest, nothing acted
  sim.step(0.0);
  EXPECT_EQ(10.0, sim.appliedForce());
  EXPECT_GT(sim.state()[1], 0.0);
}

TEST(MujocoEngine, NoiseIsOnTheObservationOnly)
{
  PerturbationParams noisy;
  noisy.noise_std = {0.01, 0.0, 0.01, 0.0};
  CartPoleSimulation clean = makeSimulation(CartPoleParams(), projectModel(), 0.05, 5);
  CartPoleSimulation sim = makeSimulation(CartPoleParams(), projectModel(), 0.05, 5, noisy);
  clean.resetRandom();
  sim.resetRandom();
  for (int i = 0; i < 10; ++i)
  {
    clean.step(i % 2 ? 10.0 : -10.0);
    sim.step(i % 2 ? 10.0 : -10.0);
    EXPECT_EQ(clean.state(), sim.state());
    EXPECT_NE(sim.state()[0], sim.observation()[0]);
    EXPECT_EQ(sim.state()[1], sim.observation()[1]);
  }
}

TEST(MujocoEngine, AWeakerMotorGivesLessOfTheClampedForce)
{
  PerturbationParams weak;
  weak.motor = {0.5, 0.5};
  CartPoleSimulation sim = makeSimulation(CartPoleParams(), projectModel(), 0.0, 1, weak);
  CartPoleSimulation full = makeSimulation(CartPoleParams(), projectModel(), 0.0, 1);
  sim.resetRandom();
  full.resetRandom();
  sim.step(30.0);  // clamped to 10 N, then halved
  full.step(5.0);
  EXPECT_DOUBLE_EQ(5.0, sim.appliedForce());
  EXPECT_EQ(1u, sim.clamps());
  EXPECT_NEAR(full.state()[1], sim.state()[1], 1e-12);
}

TEST(MujocoEngine, MassesScaleTheTwoBodies)
{
  PerturbationParams heavy;
  heavy.mass_cart = {2.0, 2.0};
  heavy.mass_pole = {3.0, 3.0};
  CartPoleSimulation sim = makeSimulation(CartPoleParams(), projectModel(), 0.0, 1, heavy);
  CartPoleSimulation nominal = makeSimulation(CartPoleParams(), projectModel(), 0.0, 1);
  sim.resetRandom();
  nominal.resetRandom();
  const auto& engine = dynamic_cast<const MujocoEngine&>(sim.engine());
  const mjModel& m = engine.model();
  const int cart = mj_name2id(&m, mjOBJ_BODY, "cart");
  const int pole = mj_name2id(&m, mjOBJ_BODY, "pole");
  EXPECT_DOUBLE_EQ(2.0, m.body_mass[cart]);
  EXPECT_DOUBLE_EQ(0.3, m.body_mass[pole]);
  EXPECT_DOUBLE_EQ(3.0 * 0.0083333333333333, m.body_inertia[3 * pole]);
  sim.step(10.0);
  nominal.step(10.0);
  // About (1 + 0.1) / (2 + 0.3) of the nominal acceleration (a pole at rest upright).
  EXPECT_NEAR(nominal.state()[1] * 1.1 / 2.3, sim.state()[1], 0.02 * nominal.state()[1]);
}

TEST(MujocoEngine, APushIsAForceOnTheCart)
{
  PerturbationParams pushes;
  pushes.push_probability = 1.0;
  pushes.push_force = 5.0;
  CartPoleSimulation sim = makeSimulation(CartPoleParams(), projectModel(), 0.0, 9, pushes);
  CartPoleSimulation motor = makeSimulation(CartPoleParams(), projectModel(), 0.0, 9);
  sim.resetRandom();
  motor.resetRandom();
  sim.step(0.0);
  ASSERT_NE(0.0, sim.lastPush());
  EXPECT_EQ(sim.lastPush(), sim.appliedForce());
  motor.step(sim.lastPush());  // the same force through the motor
  EXPECT_NEAR(motor.state()[1], sim.state()[1], 1e-12);
  const auto& engine = dynamic_cast<const MujocoEngine&>(sim.engine());
  EXPECT_EQ(0.0, engine.data().xfrc_applied[6 * 1]);  // only during its step
}

TEST(MujocoEngine, HalfLengthCannotBeDrawnForAModel)
{
  PerturbationParams longer;
  longer.half_length = {1.0, 2.0};
  EXPECT_THROW(makeSimulation(CartPoleParams(), projectModel(), 0.0, 1, longer), std::invalid_argument);
}

TEST(MujocoEngine, EachLoadErrorNamesTheKeyAndTheModel)
{
  EngineParams p = projectModel();
  const auto expectError = [](const std::string& message, const std::string& key, const std::string& model,
                              const std::string& why) {
    EXPECT_NE(message.find("physics/" + key), std::string::npos) << message;
    EXPECT_NE(message.find(model), std::string::npos) << message;
    EXPECT_NE(message.find(why), std::string::npos) << message;
  };
  p.model = "/no/such/model.xml";
  expectError(loadError(p), "model", p.model, "cannot be loaded");
  p.model = ::testing::TempDir() + "/not_mjcf.xml";
  std::ofstream(p.model) << "<robot name=\"x\"><link name=\"a\"/>";
  expectError(loadError(p), "model", p.model, "cannot be loaded");
  p = projectModel();
  p.cart_joint = "rail";
  expectError(loadError(p), "cart_joint = 'rail'", kModel,
              "no such joint (its joints: cart_joint (slide), pole_joint (hinge))");
  p = projectModel();
  p.cart_joint = "pole_joint";
  expectError(loadError(p), "cart_joint = 'pole_joint'", kModel, "a hinge joint; the cart's must be a slide joint");
  p = projectModel();
  p.pole_joint = "cart_joint";
  expectError(loadError(p), "pole_joint = 'cart_joint'", kModel, "a slide joint; the pole's must be a hinge joint");
  p = projectModel();
  p.pole_joint = "stick";
  expectError(loadError(p), "pole_joint = 'stick'", kModel, "no such joint");
  p = projectModel();
  p.actuator = "engine";
  expectError(loadError(p), "actuator = 'engine'", kModel, "no such actuator (its actuators: cart_motor)");
  p = projectModel();
  p.model = modelWith("joint=\"cart_joint\" gear", "joint=\"pole_joint\" gear", "motor_on_pole");
  expectError(loadError(p), "actuator = 'cart_motor'", p.model, "does not act on physics/cart_joint 'cart_joint'");
  p = projectModel();
  p.model = modelWith("<motor name=\"cart_motor\"", "<position name=\"cart_motor\"", "position_servo");
  expectError(loadError(p), "actuator = 'cart_motor'", p.model, "not a motor");
  p = projectModel();
  expectError(loadError(p, 0.025), "tau = '0.025'", kModel, "not a whole number of the model's timestep 0.01 s");
  expectError(loadError(p, 0.004), "tau = '0.004'", kModel, "not a whole number");
  EXPECT_EQ("", loadError(p, 0.03));
}

TEST(MujocoEngine, TheConfigMakesTheEngineAndTrainsOnIt)
{
  const auto source = loadYamlParameters(CARTPOLE_CONFIG_DIR "/mujoco_cartpole.yaml");
  const TrainingConfig config = readTrainingConfig(*source);
  EXPECT_EQ("mujoco", config.engine.name);
  EXPECT_EQ(CARTPOLE_CONFIG_DIR "/../mjcf/cartpole.xml", config.engine.model);
  HeadlessTrainer trainer(config, 0);
  const EpisodeSummary& summary = trainer.runEpisode();
  EXPECT_GT(summary.steps, 0u);
  EXPECT_TRUE(summary.terminated || summary.truncated);
}

}  // namespace
