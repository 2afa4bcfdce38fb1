#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using cartpole_qlearning::CartPoleDynamics;
using cartpole_qlearning::CartPoleParams;
using cartpole_qlearning::CartPoleState;
using cartpole_qlearning::Integrator;

namespace
{
CartPoleDynamics dynamicsWith(Integrator integrator, double tau = 0.02)
{
  CartPoleParams params;
  params.integrator = integrator;
  params.tau = tau;
  return CartPoleDynamics(params);
}

void expectStateNear(const CartPoleState& expected, const CartPoleState& actual, double tolerance)
{
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(expected[i], actual[i], tolerance) << "state[" << i << "]";
}
}  // namespace

TEST(CartPoleDynamics, OneEulerStepFromRestWorkedByHand)
{
  // Upright at rest, push +10 N. sin = 0, cos = 1, total mass 1.1, pole mass * half length 0.05:
  //   temp      = (10 + 0) / 1.1                              = 100/11
  //   thetaacc  = (0 - 100/11) / (0.5 * (4/3 - 0.1/1.1))      = -(100/11) / (41/66) = -600/41
  //   xacc      = 100/11 - 0.05 * (-600/41) * 1 / 1.1         = 100/11 + 300/451  = 400/41
  // Euler with tau 0.02: positions keep the old (zero) velocities, velocities gain tau * acc.
  const CartPoleState next = dynamicsWith(Integrator::Euler).step(CartPoleState::Zero(), 10.0);
  expectStateNear(CartPoleState(0.0, 0.02 * 400.0 / 41.0, 0.0, 0.02 * -600.0 / 41.0), next, 1e-15);
}

TEST(CartPoleDynamics, EulerPositionsAdvanceWithOldVelocities)
{
  // Moving and tilted, no force: x and theta move by tau times the velocities they had.
  const CartPoleState start(0.1, 0.5, 0.05, -0.3);
  const CartPoleState next = dynamicsWith(Integrator::Euler).step(start, 0.0);
  EXPECT_DOUBLE_EQ(0.1 + 0.02 * 0.5, next[0]);
  EXPECT_DOUBLE_EQ(0.05 + 0.02 * -0.3, next[2]);
}

// Trajectories printed by tools/gymnasium_reference.py, which follows Gymnasium
// CartPole-v1's step operation for operation. Start (0.01, -0.02, 0.03, -0.04).
const std::vector<int> kReferenceActions = {1, 1, 0, 1, 0, 0, 0, 1, 1, 1, 0, 1, 0, 0, 1, 1, 0, 0, 0, 1};
const std::vector<std::vector<double>> kGymnasiumEuler = {
    {0.009600000000000001, 0.17467919574755525, 0.0292, -0.3230687179600081},
    {0.013093583914951107, 0.36937344399176103, 0.02273862564079984, -0.6064020159998607},
    {0.020481052794786327, 0.17394104931769996, 0.010610585320802625, -0.3066446263789625},
    {0.023959873781140326, 0.3689102079328361, 0.004477692793223374, -0.5959624480242942},
    {0.031338077939797045, 0.17372587880180418, -0.00744155616726251, -0.30187245208590807},
    {0.03481259551583313, -0.021289224954454344, -0.013479005208980672, -0.011545693213184105},
    {0.03438681101674404, -0.2162153015051143, -0.013709919073244354, 0.2768541533284244},
    {0.030062504986641755, -0.020900465855356126, -0.008172836006675867, -0.020121156708118426},
    {0.029644495669534632, 0.17433773314819154, -0.008575259140838235, -0.3153714615665116},
    {0.03313125033249846, 0.36958077752646534, -0.014882688372168468, -0.6107463555807918},
    {0.04052286588302777, 0.1746699771822955, -0.027097615483784303, -0.32278788206493025},
    {0.044016265426673674, 0.37016710242610945, -0.03355337312508291, -0.6238916382067526},
    {0.05141960747519586, 0.17552928299008203, -0.04603120588921796, -0.34196208109902615},
    {0.0549301931349975, -0.018908570915150358, -0.05287044751119849, -0.06414263322701436},
    {0.054552021716694495, 0.17692997743067032, -0.05415330017573877, -0.37302665404374896},
    {0.0580906212653079, 0.37277771700535867, -0.06161383325661375, -0.6822809040600752},
    {0.06554617560541508, 0.1785630790784937, -0.07525945133781525, -0.4096147477865671},
    {0.06911743718698495, -0.01541567965083332, -0.0834517462935466, -0.14157563787280186},
    {0.06880912359396828, -0.2092494457540296, -0.08628325905100263, 0.12365683095532592},
    {0.06462413467888768, -0.013004122328851342, -0.08381012243189612, -0.19495189246938538},
};
const std::vector<std::vector<double>> kGymnasiumSemiImplicit = {
    {0.013493583914951104, 0.17467919574755525, 0.023538625640799837, -0.3230687179600081},
    {0.020882747810971405, 0.369458194801015, 0.011373894382175662, -0.6082365629312088},
    {0.02436632966736556, 0.1741790928197078, 0.005134034308488712, -0.31199300368434746},
    {0.031750880210238655, 0.36922752714365464, -0.00692701368876849, -0.6030523998628601},
    {0.03523494307578987, 0.17420314327756073, -0.01317820105357988, -0.3125593682405695},
    {0.03482037079123687, -0.02072861422764996, -0.013659429057585808, -0.0240614002002964},
    {0.03050732998405937, -0.2156520403588752, -0.008373814746649126, 0.2642807155468341},
    {0.030099098498037102, -0.020411574301113317, -0.008994446517735576, -0.031031588554322476},
    {0.033595862483716675, 0.1748381992839787, -0.015525221194601115, -0.3265387338432769},
    {0.04099941666992743, 0.37017770931053773, -0.028006759572339703, -0.6240769188869293},
    {0.04450857143681447, 0.17545773834435197, -0.03481364790255018, -0.3403444165105237},
    {0.05192971728179589, 0.37105729224907114, -0.04768963014050494, -0.6437991118977379},
    {0.055462343223591476, 0.17663129708977923, -0.05501977276067475, -0.3665071310084905},
    {0.05510899533506269, -0.017667394426439526, -0.05685312811833837, -0.09166776788318115},
    {0.05867342359051656, 0.1782214127726938, -0.06488776907578256, -0.4017320478722093},
    {0.06615744034045574, 0.37420083749695926, -0.07917069217194812, -0.714146154808278},
    {0.06976261998899276, 0.18025898242685065, -0.08811862200782586, -0.4473964917938864},
    {0.06949235745281215, -0.013513126809030274, -0.09179341046836906, -0.18373942302715968},
    {0.06534815862708443, -0.20720994128638603, -0.09022074632531865, 0.07863320715252065},
    {0.0651297938419545, -0.010918239256496404, -0.09504266150904792, -0.24109575918646348},
};

void expectGymnasiumTrajectory(Integrator integrator, const std::vector<std::vector<double>>& reference)
{
  const CartPoleDynamics dynamics = dynamicsWith(integrator);
  CartPoleState state(0.01, -0.02, 0.03, -0.04);
  for (std::size_t k = 0; k < kReferenceActions.size(); ++k)
  {
    state = dynamics.step(state, kReferenceActions[k] == 1 ? 10.0 : -10.0);
    SCOPED_TRACE("step " + std::to_string(k + 1));
    expectStateNear(CartPoleState(reference[k][0], reference[k][1], reference[k][2], reference[k][3]), state, 1e-9);
  }
}

TEST(CartPoleDynamics, EulerMatchesGymnasiumTrajectory)
{
  expectGymnasiumTrajectory(Integrator::Euler, kGymnasiumEuler);
}

TEST(CartPoleDynamics, SemiImplicitEulerMatchesGymnasiumTrajectory)
{
  expectGymnasiumTrajectory(Integrator::SemiImplicitEuler, kGymnasiumSemiImplicit);
}

TEST(CartPoleDynamics, MirroredStateAndForceGiveMirroredResult)
{
  for (Integrator integrator : {Integrator::Euler, Integrator::SemiImplicitEuler, Integrator::Rk4})
  {
    const CartPoleDynamics dynamics = dynamicsWith(integrator);
    const CartPoleState state(0.3, -0.7, 0.11, 0.9);
    const CartPoleState right = dynamics.step(state, 7.5);
    const CartPoleState left = dynamics.step(-state, -7.5);
    expectStateNear(-right, left, 1e-15);
  }
}

TEST(CartPoleDynamics, Rk4AndEulerAgreeAsTauShrinks)
{
  // Integrate one second of a swinging pole with a constant push; the gap between Euler (first
  // order) and RK4 must shrink about tenfold with each tenfold smaller tau.
  const CartPoleState start(0.0, 0.0, 0.1, 0.0);
  std::vector<double> gaps;
  for (double tau : {0.01, 0.001, 0.0001})
  {
    const CartPoleDynamics euler = dynamicsWith(Integrator::Euler, tau);
    const CartPoleDynamics rk4 = dynamicsWith(Integrator::Rk4, tau);
    CartPoleState a = start;
    CartPoleState b = start;
    const int steps = static_cast<int>(std::lround(1.0 / tau));
    for (int i = 0; i < steps; ++i)
    {
      a = euler.step(a, 2.0);
      b = rk4.step(b, 2.0);
    }
    gaps.push_back((a - b).norm());
  }
  EXPECT_GT(gaps[0], 1e-3);  // the comparison means something: the methods do differ at 10 ms
  EXPECT_LT(gaps[1], gaps[0] / 5.0);
  EXPECT_LT(gaps[2], gaps[1] / 5.0);
  EXPECT_LT(gaps[2], 1e-2);
}

TEST(CartPoleDynamics, SteppingSeveralForcesAtOnceGivesEachStepsBits)
{
  // DelayEstimator weighs its delays with stepEach; a delay found must not depend on that
  // shortcut: every integrator, with friction, and a cart past the rail's end (where the stop acts).
  const double forces[] = {-10.0, 0.0, 3.25, 10.0};
  for (Integrator integrator : {Integrator::Euler, Integrator::SemiImplicitEuler, Integrator::Rk4})
  {
    for (const bool rough : {false, true})
    {
      CartPoleParams params;
      params.integrator = integrator;
      params.rail_limit = 1.8;
      params.cart_friction = rough ? 0.0005 : 0.0;
      params.pole_friction = rough ? 0.000002 : 0.0;
      const CartPoleDynamics dynamics(params);
      for (const CartPoleState& state : {CartPoleState(0.3, -0.7, 0.11, 0.9), CartPoleState(-1.9, -0.4, 2.8, -3.0)})
      {
        CartPoleState each[4];
        dynamics.stepEach(state, forces, 4, each);
        for (int i = 0; i < 4; ++i)
          for (int k = 0; k < 4; ++k)
            EXPECT_EQ(dynamics.step(state, forces[i])[k], each[i][k])
                << "integrator " << static_cast<int>(integrator) << ", force " << forces[i] << ", state " << k;
      }
    }
  }
}

TEST(CartPoleDynamics, AVelocityChangeShowsInThePositionByTheIntegratorsShare)
{
  // DelayPredictor corrects the model's velocity change and moves the position by this share of
  // the correction: it must be what the integrator's own step does with a change of force.
  for (Integrator integrator : {Integrator::Euler, Integrator::SemiImplicitEuler, Integrator::Rk4})
  {
    const CartPoleDynamics dynamics = dynamicsWith(integrator);
    const CartPoleState state(0.3, -0.7, 0.05, 0.4);
    const CartPoleState pushed = dynamics.step(state, 10.0);
    const CartPoleState free = dynamics.step(state, 0.0);
    for (int velocity : {1, 3})
    {
      const double change = pushed[velocity] - free[velocity];
      ASSERT_GT(std::fabs(change), 1e-3);
      const double share = (pushed[velocity - 1] - free[velocity - 1]) / (dynamics.params().tau * change);
      // RK4's force acts over the whole step, so the position sees about half the velocity's change.
      EXPECT_NEAR(dynamics.velocityChangeInPosition(), share, integrator == Integrator::Rk4 ? 0.02 : 1e-9)
          << "integrator " << static_cast<int>(integrator) << ", velocity " << velocity;
    }
  }
}

TEST(CartPoleDynamics, ForceIsClampedToForceMag)
{
  const CartPoleDynamics dynamics = dynamicsWith(Integrator::Euler);
  EXPECT_EQ(10.0, dynamics.clampForce(25.0));
  EXPECT_EQ(-10.0, dynamics.clampForce(-1e9));
  EXPECT_EQ(3.5, dynamics.clampForce(3.5));
}

TEST(CartPoleDynamics, BadParametersAreRefusedWithTheirName)
{
  CartPoleParams params;
  params.mass_pole = -0.1;
  try
  {
    CartPoleDynamics dynamics(params);
    FAIL() << "a negative pole mass was accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("mass_pole = -0.1")) << e.what();
  }
  params = CartPoleParams();
  params.tau = 0.0;
  EXPECT_NE(std::string::npos, params.validate().find("tau")) << params.validate();
  params.tau = std::nan("");
  EXPECT_FALSE(params.validate().empty());
  EXPECT_THROW(cartpole_qlearning::integratorFromString("verlet"), std::invalid_argument);
  EXPECT_EQ(Integrator::Rk4, cartpole_qlearning::integratorFromString("rk4"));
}
