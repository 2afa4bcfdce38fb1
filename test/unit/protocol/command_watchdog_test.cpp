// CommandWatchdog over scripted event orders, against a robot that holds the last command it got
// (ros_control's JointEffortController): whatever the controller does, the robot is left at 0
// within the timeout (at once when the controller's publisher is gone), and said once.
#include "cartpole_qlearning/protocol/command_watchdog.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace
{
using cartpole_qlearning::CommandWatchdog;
using cartpole_qlearning::LogLine;
using cartpole_qlearning::LogLines;
using cartpole_qlearning::WallClock;
using std::chrono::milliseconds;
using Action = CommandWatchdog::Action;

const WallClock::duration kTimeout = milliseconds(100);

// The watchdog between a controller and a holding robot, on a clock the script moves. The node's
// timer ticks every 10 ms and asks for the publisher count at each tick and before each command.
class Script
{
public:
  explicit Script(WallClock::duration timeout = kTimeout) : watchdog_(timeout)
  {
    publishers(1);
  }

  // A command arrives now (the clock does not move).
  Action command(double effort)
  {
    carry(watchdog_.onPublishers(publishers_, log_), 0.0);
    const Action action = watchdog_.onCommand(effort, now_, log_);
    carry(action, effort);
    return action;
  }
  // Commands every 20 ms for `count` decisions.
  void steady(double effort, int count)
  {
    for (int i = 0; i < count; ++i)
    {
      command(effort);
      wait(milliseconds(20));
    }
  }
  void publishers(std::size_t count)
  {
    publishers_ = count;
  }
  // Time passes with the timer ticking every 10 ms; returns when the robot got 0 (or the end).
  WallClock::duration wait(WallClock::duration d)
  {
    const WallClock::time_point start = now_;
    const WallClock::time_point end = now_ + d;
    WallClock::duration zero_after = d;
    while (now_ < end)
    {
      now_ += milliseconds(10);
      const double before = zeros_;
      carry(watchdog_.onPublishers(publishers_, log_), 0.0);
      carry(watchdog_.onTick(now_, log_), 0.0);
      if (zeros_ > before && zero_after == d)
        zero_after = now_ - start;
    }
    return zero_after;
  }
  void shutdown()
  {
    carry(watchdog_.onShutdown(log_), 0.0);
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

  CommandWatchdog watchdog_;
  WallClock::time_point now_ = WallClock::time_point() + std::chrono::hours(1);
  std::size_t publishers_ = 0;
  double held_ = 0.0;  // what the robot holds
  int forwarded_ = 0;
  int zeros_ = 0;  // zeros the watchdog sent
  LogLines log_;

private:
  void carry(Action action, double effort)
  {
    if (action == Action::Forward)
    {
      held_ = effort;
      ++forwarded_;
    }
    else if (action == Action::SendZero)
    {
      held_ = 0.0;
      ++zeros_;
    }
  }
};

TEST(CommandWatchdog, SteadyCommandsAreForwardedAsTheyCome)
{
  Script s;
  for (int i = 0; i < 500; ++i)
  {
    const double effort = i % 2 == 0 ? 10.0 : -10.0;
    ASSERT_EQ(Action::Forward, s.command(effort));
    ASSERT_EQ(effort, s.held_);
    s.wait(milliseconds(20));
  }
  EXPECT_EQ(500, s.forwarded_);
  EXPECT_EQ(0, s.zeros_);
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

TEST(CommandWatchdog, AGapLongerThanTheTimeoutLeavesZeroWithinIt)
{
  Script s;
  s.steady(10.0, 10);
  // 20 ms passed since the last command: the timeout counts from it.
  const WallClock::duration after = s.wait(milliseconds(500)) + milliseconds(20);
  EXPECT_EQ(0.0, s.held_);
  EXPECT_EQ(1, s.zeros_) << "one zero, not one per tick";
  EXPECT_GE(after, kTimeout);
  EXPECT_LE(after, kTimeout + milliseconds(10)) << "within a tick of the timeout";
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find("no command for")) << s.text();
}

TEST(CommandWatchdog, AGapShorterThanTheTimeoutIsNothing)
{
  Script s;
  s.steady(10.0, 10);
  s.wait(milliseconds(60));
  s.steady(-10.0, 10);
  EXPECT_EQ(0, s.zeros_);
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

TEST(CommandWatchdog, ALostPublisherLeavesZeroAtOnce)
{
  Script s;
  s.steady(-10.0, 10);
  s.publishers(0);  // kill -9: the kernel closed its socket
  const WallClock::duration after = s.wait(milliseconds(500));
  EXPECT_EQ(0.0, s.held_);
  EXPECT_EQ(1, s.zeros_);
  EXPECT_LE(after, milliseconds(10)) << "at the first tick, not after the timeout";
  EXPECT_NE(std::string::npos, s.text().find("publisher is gone")) << s.text();
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << s.text();
}

TEST(CommandWatchdog, AStrayCommandAfterTheZeroIsDropped)
{
  // A command the dead controller sent before it died, delivered after its link closed.
  Script s;
  s.steady(10.0, 10);
  s.publishers(0);
  s.wait(milliseconds(10));
  ASSERT_EQ(0.0, s.held_);
  EXPECT_EQ(Action::Nothing, s.command(10.0));
  EXPECT_EQ(Action::Nothing, s.command(10.0));
  EXPECT_EQ(0.0, s.held_);
  s.wait(milliseconds(500));
  EXPECT_EQ(0.0, s.held_);
  EXPECT_EQ(1, s.zeros_);
  EXPECT_EQ(2, s.linesAt(LogLine::Level::Warn)) << "the zero, and the dropped commands once: " << s.text();
}

TEST(CommandWatchdog, AStrayCommandAfterATimeoutZeroIsTheControllersAndTimesOutAgain)
{
  // A controller that is alive but late: its command is its latest, forwarded; the timeout holds again.
  Script s;
  s.steady(10.0, 5);
  s.wait(milliseconds(200));
  ASSERT_EQ(1, s.zeros_);
  EXPECT_EQ(Action::Forward, s.command(-10.0));
  EXPECT_EQ(-10.0, s.held_);
  s.wait(milliseconds(200));
  EXPECT_EQ(0.0, s.held_);
  EXPECT_EQ(2, s.zeros_);
}

TEST(CommandWatchdog, TheControllerComingBackIsForwardedAgainAndSaidOnce)
{
  Script s;
  s.steady(10.0, 5);
  s.publishers(0);
  s.wait(milliseconds(300));
  // Restarted (respawn, or by hand): a new publisher, then its commands.
  s.publishers(1);
  s.wait(milliseconds(10));
  s.steady(-10.0, 50);
  EXPECT_EQ(-10.0, s.held_);
  EXPECT_EQ(1, s.zeros_);
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Info)) << s.text();
  EXPECT_NE(std::string::npos, s.text().find("are back")) << s.text();
}

TEST(CommandWatchdog, ANonFiniteCommandLeavesZeroAtOnceAndIsNeverForwarded)
{
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()})
  {
    Script s;
    s.steady(10.0, 5);
    EXPECT_EQ(Action::SendZero, s.command(bad));
    EXPECT_EQ(0.0, s.held_);
    for (int i = 0; i < 100; ++i)
    {
      EXPECT_EQ(Action::Nothing, s.command(bad));
      s.wait(milliseconds(20));
    }
    EXPECT_EQ(0.0, s.held_);
    EXPECT_EQ(1, s.zeros_);
    // A number again: forwarded.
    EXPECT_EQ(Action::Forward, s.command(5.0));
    EXPECT_EQ(5.0, s.held_);
  }
}

TEST(CommandWatchdog, DuplicatesChangeNothing)
{
  Script s;
  s.steady(10.0, 5);
  // The same command twice at once, and the publisher count told again and again.
  EXPECT_EQ(Action::Forward, s.command(10.0));
  EXPECT_EQ(Action::Forward, s.command(10.0));
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(Action::Nothing, s.watchdog_.onPublishers(1, s.log_));
  s.publishers(0);
  s.wait(milliseconds(50));
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(Action::Nothing, s.watchdog_.onPublishers(0, s.log_));
  s.wait(milliseconds(500));
  EXPECT_EQ(1, s.zeros_) << "one zero for one loss";
  EXPECT_EQ(1, s.linesAt(LogLine::Level::Warn)) << s.text();
}

TEST(CommandWatchdog, AControllerThatSentZeroAndWentQuietLeavesNothingToDo)
{
  // An episode's end, a fall in control mode: the controller's own 0, then silence or its end.
  Script s;
  s.steady(10.0, 5);
  s.command(0.0);
  s.wait(milliseconds(500));
  s.publishers(0);
  s.wait(milliseconds(100));
  s.shutdown();
  EXPECT_EQ(0, s.zeros_);
  EXPECT_EQ(0.0, s.held_);
  EXPECT_TRUE(s.log_.empty()) << s.text();
}

TEST(CommandWatchdog, ItsOwnEndLeavesZero)
{
  Script s;
  s.steady(10.0, 5);
  s.command(10.0);
  s.shutdown();
  EXPECT_EQ(0.0, s.held_);
  EXPECT_EQ(1, s.zeros_);
}

TEST(CommandWatchdog, NoTimeoutStillStopsForALostControllerAndItsOwnEnd)
{
  // A lockstep sim waits for each command as long as it takes: silence is no fault there.
  Script s(WallClock::duration::zero());
  s.steady(10.0, 5);
  s.wait(std::chrono::seconds(10));
  EXPECT_EQ(10.0, s.held_);
  s.publishers(0);
  s.wait(milliseconds(10));
  EXPECT_EQ(0.0, s.held_);
  EXPECT_EQ(1, s.zeros_);
}

TEST(CommandWatchdog, CommandsBeforeAnyPublisherCountAreForwarded)
{
  // The node may see a command before it polled the count: 0 publishers never seen > 0 is no loss.
  CommandWatchdog watchdog(kTimeout);
  LogLines log;
  EXPECT_EQ(Action::Nothing, watchdog.onPublishers(0, log));
  EXPECT_EQ(Action::Forward, watchdog.onCommand(3.0, WallClock::time_point(), log));
  EXPECT_TRUE(log.empty());
}

}  // namespace
