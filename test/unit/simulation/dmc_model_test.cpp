// The project's MJCF of DeepMind Control Suite's cart-pole (mjcf/dmc_cartpole.xml) against the
// Suite's own model file (dm_control suite/cartpole.xml, read from ../shared/anchors beside the
// clone, or CARTPOLE_DMC_SUITE_DIR at run time; skipped with a note when neither is there): both
// loaded by the MuJoCo engine and stepped side by side, the same states to 1e-9.
#include "cartpole_qlearning/simulation/mujoco_engine.h"
#include "cartpole_qlearning/simulation/physics_engine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>

using namespace cartpole_qlearning;

namespace
{
EngineParams ourModel()
{
  EngineParams params;
  params.name = "mujoco";
  params.model = CARTPOLE_SOURCE_DIR "/mjcf/dmc_cartpole.xml";
  params.cart_joint = "cart_joint";
  params.pole_joint = "pole_joint";
  params.actuator = "cart_motor";
  return params;
}

// The Suite's model, named as the Suite names its parts; empty model when it is not on this machine.
EngineParams suiteModel()
{
  const char* dir = std::getenv("CARTPOLE_DMC_SUITE_DIR");
  EngineParams params;
  params.name = "mujoco";
  params.model = std::string(dir != nullptr ? dir : CARTPOLE_DMC_SUITE_DIR) + "/cartpole.xml";
  if (!std::ifstream(params.model).good())
    params.model.clear();
  params.cart_joint = "slider";
  params.pole_joint = "hinge_1";
  params.actuator = "slide";
  return params;
}

// The largest difference of any state value over `steps` steps from `start` under the efforts
// effort(step), and whether both engines clamped the same commands.
double largestDifference(const CartPoleState& start, int steps, const std::function<double(int)>& effort)
{
  MujocoEngine ours(ourModel(), 0.01);
  MujocoEngine theirs(suiteModel(), 0.01);
  ours.setState(start);
  theirs.setState(start);
  double largest = 0.0;
  for (int i = 0; i < steps; ++i)
  {
    ours.step(effort(i), 0.0);
    theirs.step(effort(i), 0.0);
    largest = std::max(largest, (ours.state() - theirs.state()).cwiseAbs().maxCoeff());
  }
  EXPECT_EQ(theirs.clamps(), ours.clamps());
  return largest;
}
}  // namespace

TEST(DmcModel, OurModelHasTheSuitesMotorAndStep)
{
  const MujocoEngine ours(ourModel(), 0.01);
  EXPECT_EQ(1, ours.frameSkip());
  EXPECT_DOUBLE_EQ(10.0, ours.gear());
  EXPECT_DOUBLE_EQ(10.0, ours.forceLimit());
  EXPECT_EQ(1.0, ours.thetaSign());
}

TEST(DmcModel, TrajectoriesMatchTheSuitesModel)
{
  if (suiteModel().model.empty())
  {
    std::cout << "[  SKIPPED ] the Suite's cartpole.xml is not at " << CARTPOLE_DMC_SUITE_DIR
              << " (set CARTPOLE_DMC_SUITE_DIR to dm_control's suite/ folder to run this comparison)" << std::endl;
    GTEST_SKIP();
  }
  const CartPoleState hanging(0.01, -0.02, M_PI + 0.01, 0.015);
  const CartPoleState near_up(-0.05, 0.01, 0.03, -0.01);
  const double tolerance = 1e-9;
  // Left alone: the pole swings as it hangs.
  EXPECT_LT(largestDifference(hanging, 400, [](int) { return 0.0; }), tolerance);
  // Pumped at full effort, the way a swing-up does, turned every 0.3 s.
  EXPECT_LT(largestDifference(hanging, 400, [](int i) { return (i / 30) % 2 == 0 ? 10.0 : -10.0; }), tolerance);
  // A falling pole under the Suite's five efforts in a fixed pseudo-random order.
  const double efforts[5] = {-10.0, -4.0, 0.0, 4.0, 10.0};
  EXPECT_LT(largestDifference(near_up, 400, [&](int i) { return efforts[(i * 7 + i / 3) % 5]; }), tolerance);
  // Driven into the rail's end (1.8 m) and held there, then beyond the motor's limit both ways (clamped).
  const CartPoleState near_end(1.2, 0.5, 0.2, 0.0);
  EXPECT_LT(largestDifference(near_end, 400, [](int) { return 10.0; }), tolerance);
  EXPECT_LT(largestDifference(near_end, 300, [](int i) { return i < 150 ? 15.0 : -25.0; }), tolerance);
  // It really reached the end: MuJoCo's soft limit holds the cart within millimetres of 1.8 m.
  MujocoEngine ours(ourModel(), 0.01);
  ours.setState(near_end);
  for (int i = 0; i < 300; ++i)
    ours.step(10.0, 0.0);
  EXPECT_GT(ours.state()[0], 1.79);
  EXPECT_LT(ours.state()[0], 1.81);
}

TEST(DmcModel, TheEquationsRailEndsStopTheCartAsTheModelsLimitDoes)
{
  // The equations with the Suite's constants and physics/rail_limit 1.8 beside our model, driven into
  // an end: the stop imitates MuJoCo's soft limit (cartpole_dynamics.h), so that a table trained on
  // one meets the same ends on the other.
  CartPoleParams equations;
  equations.gravity = 9.81;
  equations.tau = 0.01;
  equations.integrator = Integrator::Rk4;
  equations.rail_limit = 1.8;
  for (const CartPoleState& start : {CartPoleState(1.5, 0.0, M_PI, 0.0), CartPoleState(-1.5, -3.0, M_PI, 0.0)})
  {
    EquationsEngine ours(equations);
    MujocoEngine model(ourModel(), 0.01);
    ours.setState(start);
    model.setState(start);
    const double effort = start[1] == 0.0 ? 10.0 : 0.0;
    double ours_furthest = 0.0, model_furthest = 0.0;
    for (int i = 0; i < 100; ++i)
    {
      ours.step(effort, 0.0);
      model.step(effort, 0.0);
      ours_furthest = std::max(ours_furthest, std::fabs(ours.state()[0]));
      model_furthest = std::max(model_furthest, std::fabs(model.state()[0]));
      // Within a centimetre through the impact (later the pole's inertia and the damping, which
      // differ a little, take the two apart).
      if (i < 60)
      {
        EXPECT_NEAR(model.state()[0], ours.state()[0], 0.01) << i;
      }
    }
    EXPECT_GT(model_furthest, 1.85);
    EXPECT_NEAR(model_furthest, ours_furthest, 0.01);
  }
}
