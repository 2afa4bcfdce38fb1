// ~mode control's meter over scripted reactions: time balanced and waiting, the longest stretch,
// falls, repeats that count nothing, commands beyond the motor, the report's cadence.
#include "cartpole_qlearning/application/control_meter.h"

#include <gtest/gtest.h>

using namespace cartpole_qlearning;

namespace
{
constexpr Stamp kStep = 20000000;  // 20 ms: a robot at 50 Hz

// A robot's states, stamped 20 ms apart (or `gap` when given), as the protocol reacts to them.
struct States
{
  Stamp stamp = 1000 * kStep;
  Reaction decided(double effort, bool began = false, Stamp gap = kStep)
  {
    Reaction r;
    r.answer = true;
    r.effort = effort;
    r.episode_began = began;
    r.stamp = stamp += gap;
    return r;
  }
  Reaction fallen()
  {
    Reaction r = decided(0.0);  // the zero after the fall
    r.episode_ended = true;
    return r;
  }
};

std::string text(const LogLines& log)
{
  std::string all;
  for (const LogLine& line : log)
    all += line.text + "\n";
  return all;
}
}  // namespace

TEST(ControlMeter, CountsTimeBalancedTheLongestStretchAndFalls)
{
  ControlMeter meter("", 0.02, 0.1, 10.0, 1000.0);
  States states;
  EXPECT_TRUE(meter.onReaction(states.decided(0.0), false).empty());  // waiting: the clock starts
  EXPECT_TRUE(meter.onReaction(states.decided(10.0, true), false).empty());
  for (int i = 1; i < 150; ++i)  // 3 s up
    EXPECT_TRUE(meter.onReaction(states.decided(i % 2 ? -10.0 : 10.0), false).empty());
  const LogLines fell = meter.onReaction(states.fallen(), true);
  ASSERT_EQ(1u, fell.size());
  EXPECT_EQ(LogLine::Level::Warn, fell[0].level);
  EXPECT_NE(std::string::npos, text(fell).find("control: the pole fell after 3.0 s balanced; balanced 3.0 s of"))
      << text(fell);
  for (int i = 1; i < 50; ++i)  // 1 s waiting for a start (with the fall's zero): zeros
    meter.onReaction(states.decided(0.0), false);
  meter.onReaction(states.decided(10.0, true), false);
  for (int i = 1; i < 100; ++i)  // 2 s up, going on
    meter.onReaction(states.decided(10.0), false);
  const ControlStatsValues& s = meter.stats();
  EXPECT_EQ(1u, s.falls);
  EXPECT_EQ(1u + 150u + 50u + 100u, s.decisions);
  EXPECT_NEAR(5.0, s.balanced_seconds, 1e-9);
  EXPECT_NEAR(6.0, s.seconds, 1e-9);
  EXPECT_NEAR(3.0, s.longest_seconds, 1e-9);
  EXPECT_NEAR(2.0, s.current_seconds, 1e-9);
  EXPECT_EQ(0u, s.clamped);
  EXPECT_NE(std::string::npos, meter.summary().text.find("control ended: balanced 5.0 s of 6.0 s, the longest stretch "
                                                         "3.0 s, 1 fall, 0 of 301 commands beyond the motor's 10 N"))
      << meter.summary().text;
}

TEST(ControlMeter, TimeIsTheRobotsStampsWhateverTheDecisionRate)
{
  // A 30 Hz driver, a 100 Hz one: the same 2 s of robot time. A silence counts at most max_gap;
  // a robot without stamps counts tau a decision.
  for (const Stamp gap : {Stamp(33333333), Stamp(10000000)})
  {
    ControlMeter meter("", 0.02, 0.1, 10.0, 1000.0);
    States states;
    meter.onReaction(states.decided(10.0, true, gap), false);
    const int decisions = static_cast<int>(2e9 / static_cast<double>(gap));
    for (int i = 0; i < decisions; ++i)
      meter.onReaction(states.decided(10.0, false, gap), false);
    EXPECT_NEAR(2.0, meter.stats().balanced_seconds, static_cast<double>(gap) * 1e-9) << gap;
    meter.onReaction(states.decided(10.0, false, 500 * kStep), false);  // 10 s of silence
    EXPECT_NEAR(2.1, meter.stats().balanced_seconds, static_cast<double>(gap) * 1e-9) << gap;
  }
  ControlMeter unstamped("", 0.02, 0.1, 10.0, 1000.0);
  Reaction r;
  r.answer = true;
  r.episode_began = true;
  unstamped.onReaction(r, false);
  r.episode_began = false;
  for (int i = 0; i < 99; ++i)
    unstamped.onReaction(r, false);
  EXPECT_NEAR(2.0, unstamped.stats().seconds, 1e-9);
}

TEST(ControlMeter, RepeatsAndDroppedStatesCountNothingAndAnEndThatIsNoFallIsNoFall)
{
  ControlMeter meter("robot_1", 0.02, 0.1, 10.0, 1000.0);
  States states;
  meter.onReaction(states.decided(10.0, true), false);
  meter.onReaction(states.decided(10.0), false);
  for (Reaction::Kind kind : {Reaction::Kind::Repeat, Reaction::Kind::Stale, Reaction::Kind::Stray})
  {
    Reaction r = states.decided(10.0);
    r.kind = kind;
    EXPECT_TRUE(meter.onReaction(r, false).empty());
  }
  EXPECT_EQ(2u, meter.stats().decisions);
  // Time set back (a sim restarted): the stretch is abandoned, not a fall, and the clock starts again.
  Reaction restarted = states.decided(0.0);
  restarted.stamp = kStep;
  restarted.sim_restarted = true;
  restarted.episode_began = true;
  EXPECT_TRUE(meter.onReaction(restarted, false).empty());
  EXPECT_EQ(0u, meter.stats().falls);
  EXPECT_NEAR(0.0, meter.stats().current_seconds, 1e-12);
  EXPECT_NEAR(0.02, meter.stats().seconds, 1e-12);
  // An episode that ends otherwise than by a fall is no fall.
  Reaction ended = states.decided(0.0);
  ended.episode_ended = true;
  EXPECT_TRUE(meter.onReaction(ended, false).empty());
  EXPECT_EQ(0u, meter.stats().falls);
  // A robot of several is named.
  meter.onReaction(states.decided(10.0, true), false);
  EXPECT_NE(std::string::npos, text(meter.onReaction(states.fallen(), true)).find("control (robot_1): the pole fell"));
}

TEST(ControlMeter, ReportsEveryPeriodOfRobotTimeAndCountsCommandsBeyondTheMotor)
{
  ControlMeter meter("", 0.02, 0.1, 10.0, 1.0);  // every second: 50 decisions at 50 Hz
  States states;
  int reports = 0;
  for (int i = 0; i <= 500; ++i)
  {
    const LogLines said = meter.onReaction(states.decided(i % 10 == 0 ? 15.0 : 10.0, i == 0), false);
    reports += said.empty() ? 0 : 1;
    if (!said.empty())
    {
      EXPECT_EQ(LogLine::Level::Info, said[0].level);
      EXPECT_EQ(0u, said[0].text.rfind("control: balanced ", 0)) << said[0].text;
    }
  }
  EXPECT_EQ(10, reports);
  EXPECT_EQ(51u, meter.stats().clamped);
  EXPECT_NE(std::string::npos, meter.summary().text.find("51 of 501 commands beyond the motor's 10 N"));
}

namespace
{
// A state with the pole at theta and the cart at x.
CartPoleState at(double theta, double x = 0.0)
{
  return CartPoleState(x, 0.0, theta, 0.0);
}
}  // namespace

TEST(ControlMeter, ASwingUpTableIsJudgedByTheAngleSwingUpsFallsAndTimeUpright)
{
  // The Suite's swingup never ends on the angle: no episode ends, the angle says up and down.
  ControlMeter meter("", 0.02, 0.1, 10.0, 1000.0, TaskKind::Swingup, 1.8);
  States states;
  meter.onReaction(states.decided(0.0, true), false, at(M_PI));  // hanging: the clock starts
  for (int i = 1; i < 100; ++i)                                  // 2 s swinging, down
    EXPECT_TRUE(meter.onReaction(states.decided(10.0), false, at(M_PI - 0.01 * i)).empty());
  // Through upright and on over the top: not held, no swing-up.
  for (int i = 0; i < 10; ++i)
    EXPECT_TRUE(meter.onReaction(states.decided(10.0), false, at(0.0)).empty());
  for (int i = 0; i < 50; ++i)  // 1 s down again
    meter.onReaction(states.decided(-10.0), false, at(2.0));
  // Upright at 3.2 s, held: at 1 s upright it is a swing-up that took 3.2 s.
  LogLines said;
  for (int i = 0; i <= 50 && said.empty(); ++i)
    said = meter.onReaction(states.decided(4.0), false, at(0.1));
  ASSERT_EQ(1u, said.size());
  EXPECT_EQ(LogLine::Level::Info, said[0].level);
  EXPECT_EQ(0u, said[0].text.rfind("control: swung the pole up in 3.2 s (swing-up 1); upright ", 0)) << said[0].text;
  EXPECT_EQ(1u, meter.stats().swing_ups);
  EXPECT_NEAR(3.2, meter.stats().last_swing_up_seconds, 1e-9);
  EXPECT_NEAR(1.0, meter.stats().balanced_seconds, 1e-9);
  for (int i = 0; i < 100; ++i)  // 2 s more up, leaning within 18 degrees
    EXPECT_TRUE(meter.onReaction(states.decided(0.0), false, at(i % 2 ? 0.3 : -0.3)).empty());
  // Knocked down: past the horizontal it is a fall, and the controller goes on (no episode ends).
  EXPECT_TRUE(meter.onReaction(states.decided(-10.0), false, at(1.2)).empty());  // 69 degrees: not yet
  said = meter.onReaction(states.decided(-10.0), false, at(-1.8));
  ASSERT_EQ(1u, said.size());
  EXPECT_EQ(LogLine::Level::Warn, said[0].level);
  EXPECT_NE(std::string::npos, said[0].text.find("control: the pole fell after 3.0 s balanced (below the horizontal"))
      << said[0].text;
  for (int i = 0; i < 100; ++i)  // 2 s down
    meter.onReaction(states.decided(10.0), false, at(3.0));
  for (int i = 0; i <= 50; ++i)  // up again: 2.02 s after the fall
    meter.onReaction(states.decided(0.0), false, at(-0.2));
  const ControlStatsValues& s = meter.stats();
  EXPECT_EQ(2u, s.swing_ups);
  EXPECT_EQ(1u, s.falls);
  EXPECT_NEAR(2.02, s.last_swing_up_seconds, 1e-9);
  EXPECT_NEAR(3.2, s.longest_swing_up_seconds, 1e-9);
  // Upright: 0.2 s through the top, 1.02 + 2.0 s up (not the states at 69 degrees and past the
  // horizontal, which count as balanced until the fall), 1.02 s up again.
  EXPECT_NEAR(0.2 + 3.02 + 1.02, s.upright_seconds, 1e-9);
  EXPECT_NEAR(3.04, s.longest_seconds, 1e-9);
  EXPECT_NEAR(1.0, s.current_seconds, 1e-9);
  EXPECT_EQ(0u, s.rail_hits);
  EXPECT_NE(std::string::npos, meter.summary().text.find(" (cos(theta) >= 0.95), 2 swing-ups (the last took 2.0 s, "
                                                         "the longest 3.2 s), balanced "))
      << meter.summary().text;
}

TEST(ControlMeter, ABalanceTableThatStartsUpHasNoSwingUpToCount)
{
  ControlMeter meter("", 0.01, 0.1, 10.0, 1000.0, TaskKind::Balance);
  States states;
  for (int i = 0; i < 300; ++i)
    EXPECT_TRUE(meter.onReaction(states.decided(0.0, i == 0), false, at(0.02)).empty());
  EXPECT_EQ(0u, meter.stats().swing_ups);
  EXPECT_NEAR(meter.stats().seconds, meter.stats().balanced_seconds, 1e-9);
  EXPECT_EQ(std::string::npos, meter.summary().text.find("rail")) << "no rail_limit, no hits said";
}

TEST(ControlMeter, CountsEachArrivalAtTheRailsEndsOnce)
{
  ControlMeter meter("", 0.02, 0.1, 10.0, 1000.0, TaskKind::Swingup, 1.8);
  States states;
  // Into the right end, resting against it, away a little (not left), away, into the left end.
  for (const double x : {0.0, 1.5, 1.79, 1.81, 1.8, 1.75, 1.79, 1.5, 0.0, -1.785, -1.9})
    meter.onReaction(states.decided(10.0), false, at(M_PI, x));
  EXPECT_EQ(2u, meter.stats().rail_hits);
  EXPECT_NE(std::string::npos, meter.summary().text.find(", 2 hits of the rail's ends, ")) << meter.summary().text;
  // CartPole-v1's report as it was.
  ControlMeter v1("", 0.02, 0.1, 10.0, 1000.0);
  v1.onReaction(states.decided(10.0, true), false, at(0.0, 2.0));
  EXPECT_EQ(0u, v1.stats().rail_hits);
  EXPECT_EQ(0u, v1.stats().swing_ups);
  EXPECT_EQ(0u, v1.summary().text.rfind("control ended: balanced ", 0)) << v1.summary().text;
}
