// The rules of reset_calls.h, each driven through a scripted order of events on a fake clock
// (milliseconds from 0).
#include "cartpole_qlearning/protocol/reset_calls.h"

#include "cartpole_qlearning/node_settings/node_setting_names.h"

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
// The type the calls are made with, and its md5sum (any text: only equality counts).
const std::string kType = "cartpole_qlearning/Reset";
const std::string kMd5 = "reset-md5";
const char* const kMeanwhile =
    "; retrying until it answers, and until then an episode starts only when the state is inside ~start_region";
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
  return ResetCalls(kService, kType, kMd5, kGiveUpAfter, std::chrono::milliseconds(200), nodeSettingNames());
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
                   std::string("reset call to /robot_1/cartpole_sim/reset failed: no state yet") + kMeanwhile));
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
                   std::string("reset call to /robot_1/cartpole_sim/reset failed") + kMeanwhile));
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

ServiceFound served(const std::string& type, const std::string& md5sum)
{
  return {ServiceFound::Kind::Served, type, md5sum};
}

const ServiceFound kMissing{ServiceFound::Kind::Missing, "", ""};

TEST(ResetCallsTest, AServiceOfAnotherTypeIsNamedOnceAsAnErrorWithTheParameterToSet)
{
  // Told std_srvs/Trigger; the sim serves cartpole_qlearning/Reset.
  ResetCalls reset(kService, "std_srvs/Trigger", "trigger-md5", kGiveUpAfter, std::chrono::milliseconds(200),
                   nodeSettingNames());
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  const char* const wrong_type =
      "reset service /robot_1/cartpole_sim/reset serves cartpole_qlearning/Reset, not std_srvs/Trigger as "
      "~reset_service_type asks: set ~reset_service_type to cartpole_qlearning/Reset";
  Orders orders = reset.onReturn(0, false, "", ms(10), served(kType, kMd5));
  EXPECT_TRUE(says(orders, Level::Error, std::string(wrong_type) + kMeanwhile));
  EXPECT_EQ(ms(5010), orders.wake_at) << "retried every 5 s: each call makes the server log an error";
  // Every retry finds the same: nothing more is said, the calls go on.
  for (int retry = 1; retry <= 5; ++retry)
  {
    EXPECT_FALSE(reset.onTime(ms(5000 * retry + 9)).call);
    ASSERT_TRUE(makesCall(reset.onTime(ms(5000 * retry + 10)), 0, false));
    EXPECT_TRUE(quiet(reset.onReturn(0, false, "", ms(5000 * retry + 10), served(kType, kMd5)))) << "retry " << retry;
  }
  // What is found changes: the sim went away, then came back as it was. Each change is said.
  ASSERT_TRUE(makesCall(reset.onTime(ms(30010)), 0, false));
  orders = reset.onReturn(0, false, "", ms(30015), kMissing);
  EXPECT_EQ(ms(30215), orders.wake_at) << "a missing service may come up any moment";
  EXPECT_TRUE(says(orders, Level::Error,
                   std::string("reset service /robot_1/cartpole_sim/reset is missing: no node advertises it. Start "
                               "the node that serves it, or set ~reset_service to the robot's reset service (\"\" "
                               "for none: a person stands the pole up)") +
                       kMeanwhile));
  ASSERT_TRUE(makesCall(reset.onTime(ms(30300)), 0, false));
  EXPECT_TRUE(says(reset.onReturn(0, false, "", ms(30305), served(kType, kMd5)), Level::Error,
                   std::string(wrong_type) + kMeanwhile));
  // A probe that found nothing out (timed out) after it: the call's failure, a warning.
  ASSERT_TRUE(makesCall(reset.onTime(ms(35305)), 0, false));
  EXPECT_TRUE(says(reset.onReturn(0, false, "", ms(35310), ServiceFound()), Level::Warn,
                   std::string("reset call to /robot_1/cartpole_sim/reset failed") + kMeanwhile));
}

TEST(ResetCallsTest, AServiceNobodyServesIsSaidToBeMissingOnceUntilItAnswers)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  Orders orders = reset.onReturn(0, false, "", ms(10), kMissing);
  ASSERT_EQ(1u, orders.log.size());
  EXPECT_EQ(Level::Error, orders.log[0].level);
  EXPECT_NE(std::string::npos, orders.log[0].text.find("/robot_1/cartpole_sim/reset is missing")) << orders.log[0].text;
  ASSERT_TRUE(makesCall(reset.onTime(ms(210)), 0, false));
  EXPECT_TRUE(quiet(reset.onReturn(0, false, "", ms(215), kMissing)));
  // The sim comes up: the answer is said, and a later failure of the same kind is said again.
  ASSERT_TRUE(makesCall(reset.onTime(ms(420)), 0, false));
  EXPECT_TRUE(says(reset.onReturn(0, true, "", ms(425)), Level::Info, kAnswersAgain));
  ASSERT_TRUE(makesCall(reset.request(ms(500)), 0, true));
  EXPECT_EQ(1u, reset.onReturn(0, false, "", ms(505), kMissing).log.size());
}

TEST(ResetCallsTest, AServiceOfATypeNoResetCanBeIsNamedWithTheTypesThatCan)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  EXPECT_TRUE(says(reset.onReturn(0, false, "", ms(10), served("std_srvs/SetBool", "setbool-md5")), Level::Error,
                   std::string("reset service /robot_1/cartpole_sim/reset serves std_srvs/SetBool, not "
                               "cartpole_qlearning/Reset as ~reset_service_type asks, and ~reset_service_type can "
                               "only be cartpole_qlearning/Reset, std_srvs/Empty or std_srvs/Trigger: set "
                               "~reset_service to a service of one of these (\"\" for none: a person stands the pole "
                               "up)") +
                       kMeanwhile));
}

TEST(ResetCallsTest, AServiceOfTheSameTypeButAnotherDefinitionIsNamedByItsMd5sum)
{
  ResetCalls reset = resetCalls();
  ASSERT_TRUE(makesCall(reset.request(ms(0)), 0, true));
  EXPECT_TRUE(says(reset.onReturn(0, false, "", ms(10), served(kType, "older-md5")), Level::Error,
                   std::string("reset service /robot_1/cartpole_sim/reset serves cartpole_qlearning/Reset of another "
                               "definition than this controller's (md5sum older-md5, not reset-md5): build both "
                               "against the same cartpole_qlearning/Reset") +
                       kMeanwhile));
  // A service of the type asked for, whose call still fails (success false): the call's failure.
  ResetCalls other = resetCalls();
  ASSERT_TRUE(makesCall(other.request(ms(0)), 0, true));
  EXPECT_TRUE(says(other.onReturn(0, false, "busy", ms(10), served(kType, kMd5)), Level::Warn,
                   std::string("reset call to /robot_1/cartpole_sim/reset failed: busy") + kMeanwhile));
}

TEST(ResetCallsTest, EveryCallBackAndGiveUpIsAnOutcomeForTheProtocol)
{
  ResetCalls reset = resetCalls();
  Orders orders = reset.request(ms(0));
  EXPECT_FALSE(orders.reset_done) << "a call made is no outcome";
  orders = reset.onReturn(0, true, "", ms(10));
  ASSERT_TRUE(orders.reset_done);
  EXPECT_TRUE(*orders.reset_done);
  reset.request(ms(20));
  orders = reset.onReturn(0, false, "", ms(30), kMissing);
  ASSERT_TRUE(orders.reset_done);
  EXPECT_FALSE(*orders.reset_done);
  EXPECT_FALSE(reset.onTime(ms(100)).reset_done) << "waiting for the retry";
  ASSERT_TRUE(makesCall(reset.onTime(ms(230)), 0, false));
  orders = reset.onTime(ms(5230));  // hung: given up
  ASSERT_TRUE(orders.give_up);
  ASSERT_TRUE(orders.reset_done);
  EXPECT_FALSE(*orders.reset_done);
  EXPECT_FALSE(reset.onReturn(0, true, "", ms(5240)).reset_done) << "a given-up call back late";
  orders = reset.onReturn(1, true, "", ms(5250));
  ASSERT_TRUE(orders.reset_done);
  EXPECT_TRUE(*orders.reset_done);
  reset.request(ms(6000));
  EXPECT_FALSE(reset.stop().reset_done) << "a stop is no failed reset";
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
  ResetCalls reset(kService, kType, kMd5, resetGiveUpAfter(1e300));
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
  ResetCalls reset(kService, kType, kMd5, ResetCalls::Clock::duration::max());
  const Orders orders = reset.request(ms(1000));
  ASSERT_TRUE(orders.call);
  EXPECT_EQ(kNever, orders.wake_at) << "wrapped round to the past: given up at once";
  EXPECT_TRUE(quiet(reset.onTime(ms(1000000))));
}
