// The rules of reset_calls.h, each driven through a scripted order of events on a fake clock
// (milliseconds from 0).
#include "cartpole_qlearning/protocol/reset_calls.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <string>

using namespace cartpole_qlearning;
using Orders = ResetCalls::Orders;
using Level = LogLine::Level;

namespace
{
const std::string kService = "/robot_1/cartpole_sim/reset";
const ResetCalls::Clock::duration kGiveUpAfter = std::chrono::seconds(5);
const ResetCalls::Clock::time_point kNever = ResetCalls::Clock::time_point::max();
const char* const kGivenUp =
    "reset call to /robot_1/cartpole_sim/reset has not returned after 5.0 s; giving it up and retrying on a new "
    "connection";
const char* const kAnswersAgain = "/robot_1/cartpole_sim/reset answers again; going on";

ResetCalls::Clock::time_point ms(std::int64_t n)
{
  return ResetCalls::Clock::time_point(std::chrono::milliseconds(n));
}

ResetCalls resetCalls()
{
  return ResetCalls(kService, kGiveUpAfter);
}

// Nothing to do: no call, no give-up, nothing said.
bool quiet(const Orders& orders)
{
  return !orders.call && !orders.give_up && orders.log.empty();
}

::testing::AssertionResult makesCall(const Orders& orders, std::uint64_t generation, bool persistent)
{
  if (!orders.call)
    return ::testing::AssertionFailure() << "no call";
  if (orders.call->generation != generation || orders.call->persistent != persistent)
    return ::testing::AssertionFailure() << "a call on generation " << orders.call->generation << ", "
                                         << (orders.call->persistent ? "persistent" : "fresh");
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult says(const Orders& orders, Level level, const std::string& text)
{
  if (orders.log.size() != 1)
    return ::testing::AssertionFailure() << orders.log.size() << " lines said";
  if (orders.log[0].level != level || orders.log[0].text != text)
    return ::testing::AssertionFailure() << (orders.log[0].level == Level::Warn ? "WARN " : "INFO ")
                                         << orders.log[0].text;
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(ResetCallsTest, ACallThatAnswersOnThePersistentConnection)
{
  ResetCalls reset = resetCalls();
  EXPECT_TRUE(quiet(reset.onTime(ms(0)))) << "a call without a request";
  Orders orders = reset.request(ms(10));
  EXPECT_TRUE(makesCall(orders, 0, true));
  EXPECT_FALSE(orders.give_up);
  EXPECT_TRUE(orders.log.empty());
  EXPECT_EQ(ms(5010), orders.wake_at) << "woken at the give-up time";

  orders = reset.onReturn(0, true, "", ms(20));
  EXPECT_TRUE(quiet(orders)) << "an answer from a robot that never failed is not said";
  EXPECT_EQ(kNever, orders.wake_at);
  EXPECT_TRUE(quiet(reset.onTime(ms(10000)))) << "nothing to give up";

  EXPECT_TRUE(makesCall(reset.request(ms(30)), 0, true)) << "the next episode's call, same connection";
}

TEST(ResetCallsTest, ARequestDuringACallIsServedByTheNextCall)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  // A short episode ends before the answer comes, twice.
  Orders orders = reset.request(ms(5));
  EXPECT_TRUE(quiet(orders)) << "a second call while one is under way";
  EXPECT_EQ(ms(5000), orders.wake_at) << "the call under way keeps its give-up time";
  EXPECT_TRUE(quiet(reset.request(ms(6))));

  orders = reset.onReturn(0, true, "", ms(10));
  EXPECT_TRUE(makesCall(orders, 0, true)) << "the request made during the call was lost";
  EXPECT_EQ(ms(5010), orders.wake_at);
  EXPECT_TRUE(quiet(reset.onReturn(0, true, "", ms(20)))) << "two requests during one call make one call";
}

TEST(ResetCallsTest, AFailingRobotIsRetriedEvery200MsOnFreshConnectionsUntilItAnswers)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  Orders orders = reset.onReturn(0, false, "no state yet", ms(10));
  EXPECT_TRUE(says(orders, Level::Warn,
                   "reset call to /robot_1/cartpole_sim/reset failed: no state yet; retrying until it answers"));
  EXPECT_FALSE(orders.call) << "retried in a tight loop";
  EXPECT_EQ(ms(210), orders.wake_at);
  EXPECT_TRUE(quiet(reset.onTime(ms(209))));
  EXPECT_TRUE(quiet(reset.request(ms(100)))) << "a request does not hasten the retry";

  EXPECT_TRUE(makesCall(reset.onTime(ms(210)), 0, false));
  // The call itself fails (no message): retried, not said again.
  orders = reset.onReturn(0, false, "", ms(215));
  EXPECT_TRUE(quiet(orders));
  EXPECT_EQ(ms(415), orders.wake_at);
  EXPECT_TRUE(makesCall(reset.onTime(ms(420)), 0, false));

  orders = reset.onReturn(0, true, "", ms(430));
  EXPECT_TRUE(says(orders, Level::Info, kAnswersAgain));
  EXPECT_FALSE(orders.call) << "the one request was served";
  EXPECT_TRUE(makesCall(reset.request(ms(440)), 0, true)) << "the persistent connection is not made again";

  // Failing again later is said again, and a failure without a message says none.
  EXPECT_TRUE(says(reset.onReturn(0, false, "", ms(450)), Level::Warn,
                   "reset call to /robot_1/cartpole_sim/reset failed; retrying until it answers"));
}

TEST(ResetCallsTest, AHungCallIsGivenUpAtTheGiveUpTimeAndRetriedOnANewThread)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(100)), 0, true));
  EXPECT_TRUE(quiet(reset.onTime(ms(5099))));
  Orders orders = reset.onTime(ms(5100));
  ASSERT_TRUE(orders.give_up);
  EXPECT_EQ(0u, *orders.give_up);
  EXPECT_TRUE(says(orders, Level::Warn, kGivenUp));
  EXPECT_TRUE(makesCall(orders, 1, false)) << "retried at once, on a new generation and a fresh connection";
  EXPECT_EQ(ms(10100), orders.wake_at);
  EXPECT_EQ(1u, reset.generation());
  EXPECT_EQ(1u, reset.blocked());

  orders = reset.onReturn(1, true, "", ms(5110));
  EXPECT_TRUE(says(orders, Level::Info, kAnswersAgain));
  EXPECT_TRUE(makesCall(reset.request(ms(5120)), 1, true));
}

TEST(ResetCallsTest, WhileAGivenUpCallIsBlockedTheNextIsWaitedForAsLongAsItTakes)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  ASSERT_TRUE(makesCall(reset.onTime(ms(5000)), 1, false));
  // The retry hangs behind the same stuck sim.
  Orders orders = reset.onTime(ms(10000));
  EXPECT_TRUE(quiet(orders)) << "a second call given up while the first is still blocked";
  EXPECT_EQ(kNever, orders.wake_at);
  EXPECT_TRUE(quiet(reset.onTime(ms(3600000))));
  EXPECT_EQ(1u, reset.generation());

  // The first comes back: its slot is freed, but the call under way is still waited for.
  EXPECT_TRUE(quiet(reset.onReturn(0, false, "", ms(4000000))));
  EXPECT_EQ(0u, reset.blocked());
  EXPECT_TRUE(quiet(reset.onTime(ms(4000001))));
  EXPECT_TRUE(says(reset.onReturn(1, true, "", ms(4000002)), Level::Info, kAnswersAgain));
}

TEST(ResetCallsTest, AGivenUpCallComingBackLateIsIgnoredAndFreesItsSlot)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  ASSERT_TRUE(makesCall(reset.onTime(ms(5000)), 1, false));
  ASSERT_TRUE(quiet(reset.request(ms(5500))));

  // Late and even a success: not taken for the call under way, not said, no call made.
  Orders orders = reset.onReturn(0, true, "", ms(6000));
  EXPECT_TRUE(quiet(orders));
  EXPECT_EQ(ms(10000), orders.wake_at) << "the call under way keeps its give-up time";
  EXPECT_EQ(0u, reset.blocked());

  // The slot is free: the call under way can be given up in its turn.
  orders = reset.onTime(ms(10000));
  ASSERT_TRUE(orders.give_up);
  EXPECT_EQ(1u, *orders.give_up);
  EXPECT_TRUE(makesCall(orders, 2, false));
  // Generation 1 comes back too: ignored (generation 2's call is under way, the request waits).
  EXPECT_TRUE(quiet(reset.onReturn(1, true, "", ms(10005))));
  orders = reset.onReturn(2, true, "", ms(10010));
  EXPECT_TRUE(says(orders, Level::Info, kAnswersAgain));
  EXPECT_FALSE(orders.call) << "the request made at 5.5 s was served by the retry at 10 s";
}

TEST(ResetCallsTest, AThreadGivenUpBeforeItTookItsCallFreesItsSlot)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  ASSERT_TRUE(makesCall(reset.onTime(ms(5000)), 1, false));
  EXPECT_TRUE(quiet(reset.onThreadEnded(0, ms(5001))));
  EXPECT_EQ(0u, reset.blocked());
  const Orders orders = reset.onTime(ms(10000));
  ASSERT_TRUE(orders.give_up) << "waited for as though generation 0 were still blocked";
  EXPECT_EQ(1u, *orders.give_up);
  EXPECT_TRUE(makesCall(orders, 2, false));
}

TEST(ResetCallsTest, StopGivesUpACallUnderWayAndEndsTheCalls)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  ASSERT_TRUE(quiet(reset.request(ms(1))));
  Orders orders = reset.stop();
  ASSERT_TRUE(orders.give_up) << "stop waits for the call under way";
  EXPECT_EQ(0u, *orders.give_up);
  EXPECT_TRUE(orders.log.empty()) << "a stop is not a hung robot";
  EXPECT_FALSE(orders.call);
  EXPECT_EQ(kNever, orders.wake_at);

  EXPECT_TRUE(quiet(reset.onReturn(0, true, "", ms(2)))) << "the request made during the call";
  EXPECT_TRUE(quiet(reset.request(ms(3))));
  EXPECT_TRUE(quiet(reset.onTime(ms(100000))));
}

TEST(ResetCallsTest, StopWithoutACallUnderWayGivesNothingUp)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  ASSERT_EQ(ms(201), reset.onReturn(0, false, "", ms(1)).wake_at);
  const Orders orders = reset.stop();
  EXPECT_TRUE(quiet(orders)) << "a retry that was waiting";
  EXPECT_EQ(kNever, orders.wake_at);
  EXPECT_TRUE(quiet(reset.onTime(ms(1000))));
}

TEST(ResetCallsTest, TheGiveUpTimeIsTwiceSimTimeoutAtLeast5SAndAtMostAnHour)
{
  using std::chrono::seconds;
  EXPECT_EQ(seconds(5), resetGiveUpAfter(0.1));
  EXPECT_EQ(seconds(5), resetGiveUpAfter(2.5));
  EXPECT_EQ(seconds(8), resetGiveUpAfter(4.0));
  EXPECT_EQ(seconds(3600), resetGiveUpAfter(1800.0));
  EXPECT_EQ(seconds(3600), resetGiveUpAfter(1e300)) << "a huge ~sim_timeout";
  EXPECT_EQ(seconds(3600), resetGiveUpAfter(std::numeric_limits<double>::infinity()));

  // Used as it comes, a week into the clock: no overflow, said in seconds.
  const auto week = ms(7LL * 24 * 3600 * 1000);
  ResetCalls reset(kService, resetGiveUpAfter(1e300));
  const Orders orders = reset.request(week);
  ASSERT_TRUE(orders.call);
  EXPECT_EQ(week + seconds(3600), orders.wake_at);
  EXPECT_TRUE(quiet(reset.onTime(week + seconds(3599))));
  EXPECT_TRUE(says(reset.onTime(week + seconds(3600)), Level::Warn,
                   "reset call to /robot_1/cartpole_sim/reset has not returned after 3600.0 s; giving it up and "
                   "retrying on a new connection"));
}

TEST(ResetCallsTest, AGiveUpTimeBeyondTheClockNeverOverflows)
{
  ResetCalls reset(kService, ResetCalls::Clock::duration::max());
  const Orders orders = reset.request(ms(1000));
  ASSERT_TRUE(orders.call);
  EXPECT_EQ(kNever, orders.wake_at) << "wrapped round to the past: given up at once";
  EXPECT_TRUE(quiet(reset.onTime(ms(1000000))));
}
