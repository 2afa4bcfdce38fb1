// The equations' rail ends (physics/rail_limit) and the pole's full turns: what a swing-up needs
// of the equations engine when MuJoCo is not there.
#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/simulation/physics_engine.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace cartpole_qlearning;

namespace
{
// The Suite's cart-pole as equations: RK4 at 0.01 s, gravity 9.81, the rail's ends at +-1.8 m.
CartPoleParams suiteEquations(double rail_limit = 1.8)
{
  CartPoleParams params;
  params.gravity = 9.81;
  params.tau = 0.01;
  params.integrator = Integrator::Rk4;
  params.rail_limit = rail_limit;
  return params;
}

// Kinetic plus potential energy of the equations' cart-pole (a uniform rod of half-length l on the cart).
double energy(const CartPoleParams& p, const CartPoleState& s)
{
  const double total = p.mass_cart + p.mass_pole;
  const double ml = p.mass_pole * p.half_length;
  return 0.5 * total * s[1] * s[1] + ml * std::cos(s[2]) * s[1] * s[3] +
         0.5 * (4.0 / 3.0) * ml * p.half_length * s[3] * s[3] + ml * p.gravity * std::cos(s[2]);
}
}  // namespace

TEST(RailEnds, InsideTheRailNothingChanges)
{
  EquationsEngine ended(suiteEquations());
  EquationsEngine endless(suiteEquations(0.0));
  const CartPoleState start(0.0, 0.0, M_PI - 0.1, 0.0);
  ended.setState(start);
  endless.setState(start);
  for (int i = 0; i < 150; ++i)
  {
    const double effort = (i / 20) % 2 == 0 ? 10.0 : -10.0;
    ended.step(effort, 0.0);
    endless.step(effort, 0.0);
    ASSERT_LT(std::fabs(endless.state()[0]), 1.8) << "the test drove the cart to an end at step " << i;
    ASSERT_EQ(endless.state(), ended.state()) << i;
  }
}

TEST(RailEnds, FullEffortIntoAnEndHoldsTheCartThere)
{
  EquationsEngine engine(suiteEquations());
  engine.setState(CartPoleState(1.5, 0.0, M_PI, 0.0));
  double furthest = 0.0;
  for (int i = 0; i < 500; ++i)
  {
    engine.step(10.0, 0.0);
    furthest = std::max(furthest, engine.state()[0]);
  }
  // As MuJoCo's soft limit (the Suite's model: 1.869 m at most, then 1.803 m): centimetres past the
  // end as it arrives at 2.3 m/s, then held there at rest, millimetres past it, for as long as it is pushed.
  EXPECT_GT(furthest, 1.8);
  EXPECT_LT(furthest, 1.8 + 0.1);
  EXPECT_GT(engine.state()[0], 1.8);
  EXPECT_LT(engine.state()[0], 1.8 + 0.005);
  EXPECT_LT(std::fabs(engine.state()[1]), 1e-3);
  // Let go, the stop does not hold it: the swinging pole draws the cart back onto the rail.
  for (int i = 0; i < 100; ++i)
    engine.step(0.0, 0.0);
  EXPECT_LT(engine.state()[0], 1.8);
}

TEST(RailEnds, ACartArrivingFastStopsWithoutBouncing)
{
  EquationsEngine engine(suiteEquations());
  // Hanging pole at rest, the cart at 3 m/s towards the left end.
  engine.setState(CartPoleState(-1.5, -3.0, M_PI, 0.0));
  double furthest = 0.0;
  double rebound = 0.0;
  for (int i = 0; i < 200; ++i)
  {
    engine.step(0.0, 0.0);
    furthest = std::min(furthest, engine.state()[0]);
    rebound = std::max(rebound, engine.state()[1]);
  }
  // Stopped within 10 cm past the end (critically damped, as MuJoCo's solref 0.08 1: the Suite's
  // model goes 9.2 cm past it), and sent back at under a fifth of the speed it came with (the pole,
  // swinging on, pulls the cart back too): nothing like an elastic bounce.
  EXPECT_LT(furthest, -1.8);
  EXPECT_GT(furthest, -1.9);
  EXPECT_LT(rebound, 0.6);
  // The stop acted on the cart, and through the hinge on the pole: it swings on.
  EXPECT_GT(std::fabs(std::remainder(engine.state()[2] - M_PI, 2 * M_PI)) + std::fabs(engine.state()[3]), 0.1);
}

TEST(RailEnds, TheTwoEndsMirrorEachOther)
{
  EquationsEngine right(suiteEquations());
  EquationsEngine left(suiteEquations());
  right.setState(CartPoleState(1.6, 2.0, 0.3, -1.0));
  left.setState(CartPoleState(-1.6, -2.0, -0.3, 1.0));
  for (int i = 0; i < 300; ++i)
  {
    right.step(7.0, 0.0);
    left.step(-7.0, 0.0);
    ASSERT_LT((right.state() + left.state()).cwiseAbs().maxCoeff(), 1e-12) << i;
  }
}

TEST(RailEnds, ThePoleTurnsWholeTurns)
{
  // Spun hard from upright with no force and no end in reach: theta runs past pi and 2 pi (never
  // wrapped) and RK4 keeps the energy.
  const CartPoleParams params = suiteEquations();
  EquationsEngine engine(params);
  const CartPoleState start(0.0, 0.0, 0.0, 12.0);
  engine.setState(start);
  for (int i = 0; i < 100; ++i)
    engine.step(0.0, 0.0);
  EXPECT_GT(engine.state()[2], 2 * M_PI);
  EXPECT_LT(std::fabs(engine.state()[0]), 1.8);
  EXPECT_NEAR(energy(params, start), energy(params, engine.state()), 1e-6 * std::fabs(energy(params, start)));
}

TEST(RailEnds, TheLimitIsValidated)
{
  CartPoleParams params;
  EXPECT_EQ(0.0, params.rail_limit);  // CartPole-v1's track has no ends: its task ends at 2.4 m
  params.rail_limit = -1.0;
  EXPECT_NE(std::string::npos, params.validate().find("rail_limit"));
  params.rail_limit = std::nan("");
  EXPECT_NE(std::string::npos, params.validate().find("rail_limit"));
}
