// FreshnessGuard over scripted event orders: whatever arrives instead of fresh states, the robot
// gets 0 within the bound, and the reason is said once.
#include "cartpole_qlearning/protocol/freshness_guard.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>

namespace
{
using cartpole_qlearning::FreshnessGuard;
using cartpole_qlearning::LogLine;
using cartpole_qlearning::LogLines;
using cartpole_qlearning::Stamp;
using cartpole_qlearning::WallClock;
using std::chrono::milliseconds;
using Cause = FreshnessGuard::Cause;

const WallClock::duration kBound = milliseconds(100);
const Stamp kTick = 20000000;  // 0.02 s of stamps

// A robot's states at 50 Hz and a controller deciding on each one, with a clock the script moves.
class Script
{
public:
  explicit Script(WallClock::duration bound = kBound) : guard_(bound, "/cartpole/joint_states") {}

  // A message arrives 20 ms after the one before; decided on when `decide` (a fresh state taken).
  bool message(Stamp stamp, bool valid = true, bool decide = false, const std::string& publisher = "/driver")
  {
    now_ += milliseconds(20);
    const bool taken = guard_.onMessage(stamp, valid, publisher, now_, log_);
    if (taken && decide)
      guard_.onDecision(stamp, now_, log_);
    stops_ += guard_.check(now_, log_) ? 1 : 0;
    return taken;
  }
  // Fresh states decided on, one per 20 ms, from stamp `from` on.
  Stamp freshRun(Stamp from, int count)
  {
    for (int i = 0; i < count; ++i)
      message(from + static_cast<Stamp>(i) * kTick, true, true);
    return from + static_cast<Stamp>(count) * kTick;
  }
  void wait(WallClock::duration d)
  {
    const WallClock::time_point end = now_ + d;
    while (now_ < end)
    {
      now_ += milliseconds(10);
      stops_ += guard_.check(now_, log_) ? 1 : 0;
    }
  }
  bool pushes() const
  {
    return guard_.mayPush(now_);
  }
  int linesAt(LogLine::Level level) const
  {
    int n = 0;
    for (const LogLine& line : log_)
      n += line.level == level ? 1 : 0;
    return n;
  }
  std::string text() const
  {
    std::string all;
    for (const LogLine& line : log_)
      all += line.text + "\n";
    return all;
  }

  FreshnessGuard guard_;
  WallClock::time_point now_ = WallClock::time_point() + std::chrono::hours(1);
  LogLines log_;
  int stops_ = 0;
};

// After a script that stopped the efforts: stopped for `cause`, and said once in `words`.
void expectStopWithinBound(Script& s, Cause cause, const std::string& words)
{
  EXPECT_EQ(cause, s.guard_.cause()) << s.text();
  EXPECT_TRUE(s.guard_.stopped()) << "no stop " << s.text();
  EXPECT_FALSE(s.pushes());
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find(words)) << s.text();
}

TEST(FreshnessGuard, FreshStatesKeepEffortsGoing)
{
  Script s;
  s.freshRun(kTick, 500);
  EXPECT_TRUE(s.pushes());
  EXPECT_EQ(0, s.stops_);
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

TEST(FreshnessGuard, StatesBetweenDecisionsAreFreshWithinTheBound)
{
  // A 1 kHz driver decided on every 20th state: the others are newer, just not decided on.
  FreshnessGuard guard(kBound, "r");
  LogLines log;
  WallClock::time_point now{};
  for (Stamp i = 1; i <= 2000; ++i)
  {
    now += milliseconds(1);
    ASSERT_TRUE(guard.onMessage(i * 1000000, true, "/driver", now, log));
    if (i % 20 == 0)
      guard.onDecision(i * 1000000, now, log);
    ASSERT_FALSE(guard.check(now, log));
    ASSERT_TRUE(guard.mayPush(now) || i < 20);
  }
  EXPECT_TRUE(log.empty());
}

TEST(FreshnessGuard, FrozenStampsStopWithinTheBound)
{
  Script s;
  const Stamp next = s.freshRun(kTick, 10);
  const Stamp last = next - kTick;
  EXPECT_TRUE(s.pushes());
  // The driver republishes its last message: 4 are within the bound (80 ms), the 6th is over it.
  for (int i = 0; i < 4; ++i)
    s.message(last);
  EXPECT_TRUE(s.pushes()) << "within the bound";
  EXPECT_EQ(0, s.stops_);
  s.message(last);
  s.message(last);
  EXPECT_EQ(1, s.stops_);
  expectStopWithinBound(s, Cause::Frozen, "frozen stamps");
  s.stops_ = 0;
  for (int i = 0; i < 400; ++i)  // 8 s of it, as the issue watched
    s.message(last);
  EXPECT_FALSE(s.pushes());
  EXPECT_EQ(0, s.stops_) << "one stop, not one per message";
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << "said once";
  // The driver comes back: efforts again, said once.
  s.freshRun(next, 3);
  EXPECT_TRUE(s.pushes());
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Info)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find("again")) << s.text();
}

TEST(FreshnessGuard, StampsDroppingToZeroStop)
{
  Script s;
  s.freshRun(kTick, 10);
  for (int i = 0; i < 20; ++i)
    s.message(0);
  expectStopWithinBound(s, Cause::Unstamped, "without a stamp");
}

TEST(FreshnessGuard, AnUnstampedStreamIsFreshEveryMessage)
{
  // A driver that never stamps: every state is new (ControllerProtocol takes each), none is stale.
  Script s;
  for (int i = 0; i < 100; ++i)
    s.message(0, true, true);
  EXPECT_TRUE(s.pushes());
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

TEST(FreshnessGuard, NanBurstsStopWithinTheBoundAndFreshStatesResume)
{
  Script s;
  const Stamp next = s.freshRun(kTick, 10);
  for (int i = 0; i < 3; ++i)  // a short burst, within the bound: nothing happens
    s.message(next + static_cast<Stamp>(i) * kTick, false);
  EXPECT_EQ(0, s.stops_);
  const Stamp after = s.freshRun(next + 3 * kTick, 5);
  for (int i = 0; i < 10; ++i)
    s.message(after + static_cast<Stamp>(i) * kTick, false);
  expectStopWithinBound(s, Cause::Invalid, "NaN");
  s.freshRun(after + 10 * kTick, 2);
  EXPECT_TRUE(s.pushes());
}

TEST(FreshnessGuard, SilenceStopsOnceAndSaysSo)
{
  Script s;
  s.freshRun(kTick, 10);
  s.wait(milliseconds(90));
  EXPECT_EQ(0, s.stops_);
  EXPECT_TRUE(s.pushes());
  s.wait(milliseconds(20));
  EXPECT_EQ(1, s.stops_);
  expectStopWithinBound(s, Cause::Silence, "no joint_states at all");
  s.stops_ = 0;
  s.wait(milliseconds(5000));
  EXPECT_EQ(0, s.stops_);
}

TEST(FreshnessGuard, FreshStatesNotDecidedOnAreNotCalledSilence)
{
  // A reset under way (or a pole not yet up): the robot's states keep coming, fresh, and the
  // controller decides on none. It stops all the same, and says why without blaming the driver.
  Script s;
  const Stamp after = s.freshRun(kTick, 10);
  for (int i = 0; i < 6; ++i)
    s.message(after + static_cast<Stamp>(i) * kTick);
  expectStopWithinBound(s, Cause::Silence, "fresh joint_states came and none was decided on");
  EXPECT_EQ(std::string::npos, s.text().find("no joint_states at all")) << s.text();
  s.freshRun(after + 10 * kTick, 2);
  EXPECT_TRUE(s.pushes());
}

TEST(FreshnessGuard, NothingIsStoppedBeforeTheFirstDecision)
{
  Script s;
  s.wait(milliseconds(5000));
  for (int i = 0; i < 50; ++i)
    s.message(0, false);
  EXPECT_EQ(0, s.stops_) << "no effort was ever sent";
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

TEST(FreshnessGuard, ASecondPublisherIsRefusedNamingBothAndTheFirstStopsItsEfforts)
{
  Script s;
  const Stamp next = s.freshRun(kTick, 10);
  // Two interleaved streams: the second driver's states are refused, said once as an error.
  for (int i = 0; i < 50; ++i)
  {
    EXPECT_TRUE(s.message(next + static_cast<Stamp>(2 * i) * kTick, true, true, "/driver"));
    EXPECT_FALSE(s.message(next + static_cast<Stamp>(2 * i + 1) * kTick, true, true, "/second_driver"));
  }
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Error)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find("/driver and /second_driver")) << s.text();
  EXPECT_TRUE(s.pushes()) << "the first driver's states are still decided on";
  // The first goes silent; the second alone never becomes fresh until the first has gone.
  for (int i = 0; i < 10; ++i)
    s.message(next + static_cast<Stamp>(200 + i) * kTick, true, false, "/second_driver");
  EXPECT_FALSE(s.pushes());
  EXPECT_EQ(1, s.stops_);
  EXPECT_EQ(Cause::SecondDriver, s.guard_.cause());
}

TEST(FreshnessGuard, ADriverRestartedUnderANewNameTakesOverOnceTheOldOneIsGone)
{
  Script s;
  const Stamp next = s.freshRun(kTick, 10);
  s.wait(milliseconds(2100));
  EXPECT_TRUE(s.message(next, true, true, "/driver_restarted"));
  EXPECT_TRUE(s.pushes());
  EXPECT_EQ(0, s.linesAt(LogLine::Level::Error)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find("now come from /driver_restarted")) << s.text();
}

TEST(FreshnessGuard, AStrayPublisherDoesNotTakeThePlaceOfASimWaitingToRepeat)
{
  // A lockstep sim whose answer was lost is silent for its lockstep_timeout (0.5 s) and then
  // publishes its state again; a stray publisher flooding the topic meanwhile stays refused.
  Script s;
  const Stamp next = s.freshRun(kTick, 10);
  for (int i = 0; i < 30; ++i)  // 0.6 s of the stray alone
    EXPECT_FALSE(s.message(next + static_cast<Stamp>(i) * kTick, true, false, "/stray")) << i;
  EXPECT_TRUE(s.message(next - kTick, true, false, "/driver")) << "the sim's repeat";
  EXPECT_EQ(std::string::npos, s.text().find("now come from")) << s.text();
}

TEST(FreshnessGuard, AStampJumpForwardThenBackStops)
{
  Script s;
  const Stamp next = s.freshRun(kTick, 10);
  s.message(next + 1000 * kTick, true, true);  // a jump forward, decided on
  for (int i = 0; i < 10; ++i)                 // then back where it was: older, dropped
    s.message(next + static_cast<Stamp>(i + 1) * kTick);
  expectStopWithinBound(s, Cause::Older, "older");
}

TEST(FreshnessGuard, ABoundOfZeroIsOff)
{
  Script s(WallClock::duration::zero());
  const Stamp next = s.freshRun(kTick, 10);
  for (int i = 0; i < 100; ++i)
    s.message(next - kTick);
  s.wait(milliseconds(5000));
  // No publisher is refused either: a stray one beside a lockstep sim is the protocol's (stamps).
  for (int i = 0; i < 10; ++i)
  {
    EXPECT_TRUE(s.message(next + static_cast<Stamp>(i) * kTick, true, false, "/driver"));
    EXPECT_TRUE(s.message(next + static_cast<Stamp>(i) * kTick, true, false, "/stray"));
  }
  EXPECT_FALSE(s.guard_.enabled());
  EXPECT_TRUE(s.pushes());
  EXPECT_EQ(0, s.stops_);
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

}  // namespace

TEST(FreshnessGuard, AStreamThatComesAndGoesIsStoppedEachTimeAndSaidOncePerTenSeconds)
{
  Script s;
  Stamp next = kTick;
  for (int i = 0; i < 20; ++i)  // 20 gaps of 0.2 s in 4 s: each one stops the efforts
  {
    next = s.freshRun(next, 5);
    s.wait(milliseconds(200));
    EXPECT_FALSE(s.pushes());
  }
  EXPECT_EQ(20, s.stops_);
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << s.text();
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Info)) << "back, once: after the stop that was said";
  s.wait(milliseconds(10000));
  s.freshRun(next, 5);
  s.wait(milliseconds(200));
  EXPECT_EQ(2, s.linesAt(LogLine::Level::Warn)) << "ten seconds on, a stop is said again";
}

TEST(FreshnessGuard, ANewCauseIsSaidWithinTenSecondsOfAStopForAnother)
{
  // A hiccup of silence (a loaded machine), then, a second later, a driver whose stamps drop to
  // 0: the second stop has another cause and is said too; a second hiccup is not.
  Script s;
  Stamp next = s.freshRun(kTick, 10);
  s.wait(milliseconds(200));
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << s.text();
  next = s.freshRun(next, 50);
  for (int i = 0; i < 20; ++i)
    s.message(0);
  EXPECT_EQ(Cause::Unstamped, s.guard_.cause());
  EXPECT_EQ(2, s.linesAt(LogLine::Level::Warn)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find("without a stamp")) << s.text();
  next = s.freshRun(next, 50);
  s.wait(milliseconds(200));
  EXPECT_EQ(2, s.linesAt(LogLine::Level::Warn)) << "silence again within 10 s: not said again\n" << s.text();
}
