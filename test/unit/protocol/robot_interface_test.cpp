// Reading and driving another cart-pole (robot_interface.h): offsets, signs, whole turns, velocities
// estimated for a position-only driver, and decisions every period whatever the states' rate.
#include "cartpole_qlearning/protocol/robot_interface.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace cartpole_qlearning;

namespace
{
constexpr Stamp kMs = 1000000;  // one millisecond in stamp units [ns]

JointReadings withVelocities(double cart, double cart_v, double pole, double pole_v)
{
  return {cart, pole, cart_v, pole_v};
}

JointReadings positionsOnly(double cart, double pole)
{
  return {cart, pole, std::nullopt, std::nullopt};
}
}  // namespace

TEST(WrapAngle, WrapsIntoMinusPiExclusivePiInclusive)
{
  EXPECT_DOUBLE_EQ(0.0, wrapAngle(0.0));
  EXPECT_DOUBLE_EQ(M_PI, wrapAngle(M_PI));
  EXPECT_DOUBLE_EQ(M_PI, wrapAngle(-M_PI));
  EXPECT_NEAR(0.1, wrapAngle(2.0 * M_PI + 0.1), 1e-12);
  EXPECT_NEAR(-0.1, wrapAngle(-4.0 * M_PI - 0.1), 1e-12);
  EXPECT_NEAR(-M_PI + 0.2, wrapAngle(M_PI + 0.2), 1e-12);
}

TEST(StateMapping, TheDefaultsPassOurSimsStateThroughUnchanged)
{
  StateMapping mapping{RobotInterfaceParams()};
  const CartPoleState s = mapping.map(20 * kMs, withVelocities(0.3, -0.4, 0.05, 1.5));
  EXPECT_EQ(CartPoleState(0.3, -0.4, 0.05, 1.5), s);
  EXPECT_EQ(2.5, robotEffort(RobotInterfaceParams(), 2.5));
}

TEST(StateMapping, AppliesTheOffsetsSignsAndWholeTurns)
{
  RobotInterfaceParams params;
  params.cart_zero = 1.0;
  params.cart_sign = -1.0;
  params.pole_upright = -0.25;  // OSKOOO's pole reads -0.25 rad upright, the other sign
  params.pole_angle_sign = -1.0;
  params.effort_sign = -1.0;
  StateMapping mapping(params);
  const CartPoleState s = mapping.map(20 * kMs, withVelocities(1.5, 0.2, -0.25 - 0.1 + 4.0 * M_PI, 0.7));
  EXPECT_NEAR(-0.5, s[0], 1e-12);
  EXPECT_NEAR(-0.2, s[1], 1e-12);
  EXPECT_NEAR(0.1, s[2], 1e-12);  // two whole turns away, leaning the other way
  EXPECT_NEAR(-0.7, s[3], 1e-12);
  EXPECT_EQ(-3.0, robotEffort(params, 3.0));
}

TEST(StateMapping, WithoutVelocitiesEstimatesThemFromSuccessivePositionsOverTheStampGap)
{
  StateMapping mapping{RobotInterfaceParams()};
  // The first message has nothing to difference against.
  EXPECT_EQ(CartPoleState(0.0, 0.0, 0.0, 0.0), mapping.map(10 * kMs, positionsOnly(0.0, 0.0)));
  const CartPoleState s = mapping.map(30 * kMs, positionsOnly(0.02, -0.01));
  EXPECT_NEAR(1.0, s[1], 1e-9);
  EXPECT_NEAR(-0.5, s[3], 1e-9);
  // A repeat of the same stamp keeps the estimate; a continuous joint crossing pi gives no spike.
  EXPECT_NEAR(1.0, mapping.map(30 * kMs, positionsOnly(0.02, -0.01))[1], 1e-9);
  StateMapping turning{RobotInterfaceParams()};
  turning.map(0 + kMs, positionsOnly(0.0, M_PI - 0.01));
  EXPECT_NEAR(1.0, turning.map(21 * kMs, positionsOnly(0.0, M_PI + 0.01))[3], 1e-9);
}

TEST(StateMapping, SmoothingMixesTheNewDifferenceWithTheEstimateBefore)
{
  RobotInterfaceParams params;
  params.velocity_smoothing = 0.5;
  StateMapping mapping(params);
  mapping.map(kMs, positionsOnly(0.0, 0.0));
  EXPECT_NEAR(0.5, mapping.map(11 * kMs, positionsOnly(0.01, 0.0))[1], 1e-9);   // 0.5 * 0 + 0.5 * 1
  EXPECT_NEAR(0.75, mapping.map(21 * kMs, positionsOnly(0.02, 0.0))[1], 1e-9);  // 0.5 * 0.5 + 0.5 * 1
}

TEST(StateMapping, TimeSetBackRestartsTheEstimateAtZero)
{
  StateMapping mapping{RobotInterfaceParams()};
  mapping.map(1000 * kMs, positionsOnly(0.0, 0.0));
  EXPECT_NEAR(1.0, mapping.map(1010 * kMs, positionsOnly(0.01, 0.0))[1], 1e-9);
  EXPECT_EQ(0.0, mapping.map(5 * kMs, positionsOnly(0.5, 0.0))[1]);
  EXPECT_NEAR(-1.0, mapping.map(15 * kMs, positionsOnly(0.49, 0.0))[1], 1e-9);
}

TEST(DecisionClock, HundredHertzStatesGiveADecisionEveryTwentyMilliseconds)
{
  DecisionClock clock(0.02);
  int decided = 0;
  for (Stamp t = 10 * kMs; t <= 1000 * kMs; t += 10 * kMs)
  {
    const DecisionClock::Verdict v = clock.onState(t);
    decided += v.decide ? 1 : 0;
    EXPECT_EQ((t / (10 * kMs)) % 2 == 1, v.decide) << t;
    EXPECT_FALSE(v.slow);
  }
  EXPECT_EQ(50, decided);
}

TEST(DecisionClock, OurSimsStatesEveryTauAreEachDecidedAndRepeatsPassOn)
{
  DecisionClock clock(0.02);
  for (Stamp t = 20 * kMs; t <= 200 * kMs; t += 20 * kMs)
  {
    EXPECT_TRUE(clock.onState(t).decide);
    EXPECT_TRUE(clock.onState(t).decide);  // the lockstep sim's repeat: the protocol answers it
  }
}

TEST(DecisionClock, JitterWithinATwentiethOfThePeriodStillDecides)
{
  DecisionClock clock(0.02);
  EXPECT_TRUE(clock.onState(100 * kMs).decide);
  EXPECT_TRUE(clock.onState(119 * kMs + 500000).decide);
  EXPECT_FALSE(clock.onState(129 * kMs).decide);
}

TEST(DecisionClock, SlowerStatesAreEachDecidedAndSaidSlow)
{
  DecisionClock clock(0.02);
  EXPECT_FALSE(clock.onState(33 * kMs).slow);
  const DecisionClock::Verdict v = clock.onState(66 * kMs);  // 30 Hz
  EXPECT_TRUE(v.decide);
  EXPECT_TRUE(v.slow);
}

TEST(DecisionClock, AJitteryDriverIsDecidedOnceAPeriodAndNotSaidSlowButAThirtyHertzOneIs)
{
  // A real-time driver's states 20 ms apart give or take 3 ms (a state often comes a little early
  // for a decision a period after the last decided one): each is decided, none said slow. At
  // 100 Hz with the same jitter, every other one is decided.
  for (const Stamp every : {20 * kMs, 10 * kMs})
  {
    DecisionClock clock(0.02);
    int decided = 0;
    int slow = 0;
    for (Stamp i = 0; i < 3000; ++i)
    {
      const Stamp jitter = static_cast<Stamp>((i * 7919) % 31) * 200000 - 3000000;  // -3 .. +3 ms
      const DecisionClock::Verdict v = clock.onState(1000 * kMs + every * i + jitter);
      decided += v.decide ? 1 : 0;
      slow += v.slow ? 1 : 0;
    }
    EXPECT_EQ(every == 20 * kMs ? 3000 : 1500, decided) << every;
    EXPECT_EQ(0, slow) << every;
  }
  // A 30 Hz driver: every state is decided, and the rate is said slow from the start.
  DecisionClock thirty(0.02);
  thirty.onState(1000 * kMs);
  for (Stamp s = 1033 * kMs; s < 2000 * kMs; s += 33 * kMs)
  {
    const DecisionClock::Verdict v = thirty.onState(s);
    EXPECT_TRUE(v.decide);
    EXPECT_TRUE(v.slow);
  }
}

TEST(DecisionClock, TimeSetBackAndUnstampedStatesPassAndAPeriodOfZeroDecidesEveryMessage)
{
  DecisionClock clock(0.02);
  clock.onState(5000 * kMs);
  EXPECT_TRUE(clock.onState(10 * kMs).decide);  // a Gazebo reset: the protocol judges it
  EXPECT_FALSE(clock.onState(20 * kMs).decide);
  EXPECT_TRUE(clock.onState(0).decide);
  DecisionClock every(0.0);
  EXPECT_TRUE(every.onState(kMs).decide);
  EXPECT_TRUE(every.onState(kMs + 1).decide);
}

TEST(RobotReadings, WhatTheSimPublishesPosingAsARobotMapsBackToItsState)
{
  RobotInterfaceParams params;
  params.cart_zero = 0.5;
  params.cart_sign = -1.0;
  params.pole_upright = -0.25;
  params.pole_angle_sign = -1.0;
  const CartPoleState state(0.3, -0.2, 0.05, 0.4);
  const JointReadings r = robotReadings(params, state, 3, true);
  EXPECT_NEAR(0.2, r.cart_position, 1e-12);
  EXPECT_NEAR(-0.3 + 6.0 * M_PI, r.pole_position, 1e-12);
  StateMapping mapping(params);
  const CartPoleState back = mapping.map(kMs, r);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(state[i], back[i], 1e-9) << i;
  EXPECT_FALSE(robotReadings(params, state, 0, false).cart_velocity.has_value());
}

// The sim posing at another joint_states rate: 100 Hz samples of 50 Hz physics (gym-gazebo's rate).
TEST(SampledPhysics, SamplesTwiceAsFastAsTheStepsWaitOnlyForTheStatesWhoseAnswerDrivesAStep)
{
  SampledPhysics physics(20 * kMs, 10 * kMs);
  physics.restart(10 * kMs);  // a start state at 10 ms
  EXPECT_TRUE(physics.answerDrivesAStep(10 * kMs));
  EXPECT_EQ(1u, physics.stepsAfter(10 * kMs));
  // The state at 20 ms still shows the start: the step ends at 30 ms.
  EXPECT_TRUE(physics.showsBeforeLastStep(20 * kMs));
  EXPECT_FALSE(physics.answerDrivesAStep(20 * kMs));
  EXPECT_EQ(0u, physics.stepsAfter(20 * kMs));
  EXPECT_FALSE(physics.showsBeforeLastStep(30 * kMs));
  EXPECT_TRUE(physics.answerDrivesAStep(30 * kMs));
  EXPECT_EQ(1u, physics.stepsAfter(30 * kMs));
  // A reset between two steps starts the physics anew at its stamp.
  physics.restart(40 * kMs);
  EXPECT_FALSE(physics.showsBeforeLastStep(40 * kMs));
  EXPECT_TRUE(physics.answerDrivesAStep(40 * kMs));
}

TEST(SampledPhysics, ThirtyHzSamplesOfFiftyHzPhysicsTakeOneOrTwoStepsAndNeverShowTheFuture)
{
  const Stamp period = 33333333;  // 30 Hz (openai_ros' joint_state_controller)
  SampledPhysics physics(20 * kMs, period);
  physics.restart(period);
  std::uint64_t steps = 0;
  Stamp physics_time = period;  // the time of the physics state after the steps so far
  for (Stamp stamp = period; stamp < 100 * period; stamp += period)
  {
    ASSERT_TRUE(physics.answerDrivesAStep(stamp));  // a step starts in every 33 ms
    const std::uint64_t n = physics.stepsAfter(stamp);
    EXPECT_TRUE(n == 1 || n == 2) << n;
    steps += n;
    physics_time += n * 20 * kMs;
    // The next state shows the physics at its last step at or before it.
    const Stamp shown = physics.showsBeforeLastStep(stamp + period) ? physics_time - 20 * kMs : physics_time;
    EXPECT_LE(shown, stamp + period);
    EXPECT_GT(shown + 20 * kMs, stamp + period);
  }
  // 99 samples of 33.3 ms: 3.3 s of physics, 165 steps.
  EXPECT_EQ(165u, steps);
}

TEST(SampledPhysics, SamplesSlowerThanTheStepsTakeSeveralStepsEach)
{
  SampledPhysics physics(20 * kMs, 40 * kMs);  // 25 Hz samples
  physics.restart(40 * kMs);
  EXPECT_EQ(2u, physics.stepsAfter(40 * kMs));
  EXPECT_FALSE(physics.showsBeforeLastStep(80 * kMs));
  EXPECT_EQ(2u, physics.stepsAfter(80 * kMs));
}
