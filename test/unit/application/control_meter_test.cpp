// ~mode control's meter over scripted reactions: time balanced and waiting, the longest stretch,
// falls, repeats that count nothing, commands beyond the motor, the report's cadence.
#include "cartpole_qlearning/application/control_meter.h"

#include <gtest/gtest.h>

using namespace cartpole_qlearning;

namespace
{
Reaction decided(double effort, bool began = false)
{
  Reaction r;
  r.answer = true;
  r.effort = effort;
  r.episode_began = began;
  return r;
}

Reaction fallen()
{
  Reaction r;
  r.episode_ended = true;
  r.answer = true;  // the zero after the fall
  return r;
}

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
  ControlMeter meter("", 0.02, 10.0, 1000.0);
  EXPECT_TRUE(meter.onReaction(decided(10.0, true), false).empty());
  for (int i = 1; i < 150; ++i)  // 3 s up
    EXPECT_TRUE(meter.onReaction(decided(i % 2 ? -10.0 : 10.0), false).empty());
  const LogLines fell = meter.onReaction(fallen(), true);
  ASSERT_EQ(1u, fell.size());
  EXPECT_EQ(LogLine::Level::Warn, fell[0].level);
  EXPECT_NE(std::string::npos, text(fell).find("control: the pole fell after 3.0 s balanced; balanced 3.0 s of"))
      << text(fell);
  for (int i = 0; i < 50; ++i)  // 1 s waiting for a start: zeros
    meter.onReaction(decided(0.0), false);
  meter.onReaction(decided(10.0, true), false);
  for (int i = 1; i < 100; ++i)  // 2 s up, going on
    meter.onReaction(decided(10.0), false);
  const ControlStatsValues& s = meter.stats();
  EXPECT_EQ(1u, s.falls);
  EXPECT_EQ(150u + 1u + 50u + 100u, s.decisions);
  EXPECT_NEAR(5.0, s.balanced_seconds, 1e-9);
  EXPECT_NEAR(6.02, s.seconds, 1e-9);
  EXPECT_NEAR(3.0, s.longest_seconds, 1e-9);
  EXPECT_NEAR(2.0, s.current_seconds, 1e-9);
  EXPECT_EQ(0u, s.clamped);
  EXPECT_NE(std::string::npos, meter.summary().text.find("control ended: balanced 5.0 s of 6.0 s, the longest stretch "
                                                         "3.0 s, 1 fall, 0 of 301 commands beyond the motor's 10 N"))
      << meter.summary().text;
}

TEST(ControlMeter, RepeatsAndDroppedStatesCountNothingAndAnEndThatIsNoFallIsNoFall)
{
  ControlMeter meter("robot_1", 0.02, 10.0, 1000.0);
  meter.onReaction(decided(10.0, true), false);
  for (Reaction::Kind kind : {Reaction::Kind::Repeat, Reaction::Kind::Stale, Reaction::Kind::Stray})
  {
    Reaction r = decided(10.0);
    r.kind = kind;
    EXPECT_TRUE(meter.onReaction(r, false).empty());
  }
  EXPECT_EQ(1u, meter.stats().decisions);
  // Time set back (a sim restarted): the episode is abandoned, not a fall.
  Reaction restarted = decided(0.0);
  restarted.episode_ended = true;
  EXPECT_TRUE(meter.onReaction(restarted, false).empty());
  EXPECT_EQ(0u, meter.stats().falls);
  EXPECT_EQ(0.0, meter.stats().current_seconds);
  // A robot of several is named.
  meter.onReaction(decided(10.0, true), false);
  EXPECT_NE(std::string::npos, text(meter.onReaction(fallen(), true)).find("control (robot_1): the pole fell"));
}

TEST(ControlMeter, ReportsEveryPeriodOfRobotTimeAndCountsCommandsBeyondTheMotor)
{
  ControlMeter meter("", 0.02, 10.0, 1.0);  // every 50 decisions
  int reports = 0;
  for (int i = 0; i < 500; ++i)
  {
    const LogLines said = meter.onReaction(decided(i % 10 == 0 ? 15.0 : 10.0, i == 0), false);
    reports += said.empty() ? 0 : 1;
    if (!said.empty())
    {
      EXPECT_EQ(LogLine::Level::Info, said[0].level);
      EXPECT_EQ(0u, said[0].text.rfind("control: balanced ", 0)) << said[0].text;
    }
  }
  EXPECT_EQ(10, reports);
  EXPECT_EQ(50u, meter.stats().clamped);
  EXPECT_NE(std::string::npos, meter.summary().text.find("50 of 500 commands beyond the motor's 10 N"));
}
