// The rules of lockstep_protocol.h, each driven through a scripted order of messages, and the
// whole loop wired by hand with faults injected, which must train exactly as without them.
#include "test_support.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "lockstep_loopback.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

using cartpole_qlearning::test::bitIdentical;
using namespace cartpole_qlearning;

namespace
{
const Stamp kTick = 20000000;  // tau = 0.02 s, the shipped config's
const WallClock::duration kRepeatAfter = std::chrono::milliseconds(500);
const WallClock::duration kNs = std::chrono::nanoseconds(1);
const WallClock::time_point kT0{};  // a fake wall clock: only differences matter

// The stamp of the n-th tick of sim time.
Stamp tick(std::uint64_t n)
{
  return n * kTick;
}

TrainingConfig shippedConfig()
{
  return readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/cartpole.yaml"));
}

// The shipped config, trained for exactly `episodes` episodes.
TrainingConfig shortConfig(std::uint64_t episodes)
{
  TrainingConfig config = shippedConfig();
  config.limits.max_episodes = episodes;
  config.limits.stop_when_solved = false;
  return config;
}

CartPoleState leaning(double theta)
{
  return CartPoleState(0.0, 0.0, theta, 0.0);
}

// Well inside every threshold and inside the default start region (0.05).
const CartPoleState kUpright = CartPoleState::Zero();
const CartPoleState kSmall = leaning(0.01);
// Not terminal (12 degrees = 0.209 rad) but outside the start region.
const CartPoleState kLeaning = leaning(0.1);
const CartPoleState kFallen = leaning(0.5);

}  // namespace

// --- tickOf ----------------------------------------------------------------------------------

TEST(SimProtocol, TickOfRoundsTauToNanosecondsAndRefusesUnusableTicks)
{
  EXPECT_EQ(20000000u, tickOf(0.02));
  EXPECT_EQ(1u, tickOf(0.6e-9));
  EXPECT_THROW(tickOf(0.0), std::invalid_argument);
  EXPECT_THROW(tickOf(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(tickOf(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(tickOf(-0.02), std::invalid_argument);
  EXPECT_THROW(tickOf(0.4e-9), std::invalid_argument);  // rounds to 0 ns
  EXPECT_THROW(SimProtocol(0, kRepeatAfter), std::invalid_argument);
}

// --- SimProtocol -----------------------------------------------------------------------------

TEST(SimProtocol, ACommandWithThePendingStampStepsAndTheNextStateIsOneTickLater)
{
  SimProtocol sim(kTick, kRepeatAfter);
  EXPECT_EQ(tick(1), sim.start(kT0));
  EXPECT_EQ(tick(1), sim.pending());
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(1), kT0));
  EXPECT_EQ(tick(2), sim.pending());
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(2), kT0));
  EXPECT_EQ(tick(3), sim.pending());
  EXPECT_EQ(2u, sim.counts().steps);
  EXPECT_STREQ("", describe(SimProtocol::Verdict::Step));
}

TEST(SimProtocol, ASecondAnswerToTheSameStateIsADuplicateAndDoesNotStep)
{
  // The answer to a repeat whose first answer also arrived.
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  ASSERT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(1), kT0));
  EXPECT_EQ(SimProtocol::Verdict::Duplicate, sim.onCommand(tick(1), kT0));
  EXPECT_EQ(SimProtocol::Verdict::Duplicate, sim.onCommand(tick(1), kT0));
  EXPECT_EQ(tick(2), sim.pending());
  EXPECT_EQ(1u, sim.counts().steps);
  EXPECT_EQ(2u, sim.counts().duplicate);
  EXPECT_STRNE("", describe(SimProtocol::Verdict::Duplicate));
}

TEST(SimProtocol, StaleFutureAndUnstampedCommandsAreDroppedAndCounted)
{
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  for (std::uint64_t n = 1; n <= 3; ++n)
    ASSERT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(n), kT0));
  ASSERT_EQ(tick(4), sim.pending());

  EXPECT_EQ(SimProtocol::Verdict::Stale, sim.onCommand(tick(1), kT0));
  EXPECT_EQ(SimProtocol::Verdict::Stale, sim.onCommand(tick(2), kT0));
  EXPECT_EQ(SimProtocol::Verdict::Stale, sim.onCommand(tick(4) - 1, kT0));  // off the tick grid
  EXPECT_EQ(SimProtocol::Verdict::Future, sim.onCommand(tick(5), kT0));
  EXPECT_EQ(SimProtocol::Verdict::Future, sim.onCommand(tick(4) + 1, kT0));
  EXPECT_EQ(SimProtocol::Verdict::Future, sim.onCommand(tick(1000), kT0));
  EXPECT_EQ(SimProtocol::Verdict::Unstamped, sim.onCommand(0, kT0));

  EXPECT_EQ(tick(4), sim.pending());
  EXPECT_EQ(3u, sim.counts().steps);
  EXPECT_EQ(3u, sim.counts().stale);
  EXPECT_EQ(3u, sim.counts().future);
  EXPECT_EQ(1u, sim.counts().unstamped);
  EXPECT_EQ(0u, sim.counts().duplicate);
  EXPECT_STRNE("", describe(SimProtocol::Verdict::Stale));
  EXPECT_STRNE("", describe(SimProtocol::Verdict::Future));
  EXPECT_STRNE("", describe(SimProtocol::Verdict::Unstamped));
}

TEST(SimProtocol, AnUnstampedCommandAnswersWhateverIsPending)
{
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onUnstampedCommand(kT0));
  EXPECT_EQ(tick(2), sim.pending());
  // It answered tick 1: a stamped answer to tick 1 now comes second.
  EXPECT_EQ(SimProtocol::Verdict::Duplicate, sim.onCommand(tick(1), kT0));
  EXPECT_EQ(tick(3), sim.onReset(kT0));
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onUnstampedCommand(kT0));
  EXPECT_EQ(tick(4), sim.pending());
  EXPECT_EQ(2u, sim.counts().steps);
}

TEST(SimProtocol, AnAnswerInFlightAcrossAUserResetIsStaleAndTheNewStateIsAnsweredNormally)
{
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  ASSERT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(1), kT0));
  // The controller is answering tick 2 when a user calls ~reset.
  EXPECT_EQ(tick(3), sim.onReset(kT0));
  EXPECT_EQ(SimProtocol::Verdict::Stale, sim.onCommand(tick(2), kT0));
  EXPECT_EQ(tick(3), sim.pending());
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(3), kT0));
  EXPECT_EQ(tick(4), sim.pending());
  EXPECT_EQ(2u, sim.counts().steps);
  EXPECT_EQ(1u, sim.counts().stale);
  EXPECT_EQ(1u, sim.counts().resets);
}

TEST(SimProtocol, ARepeatIsDueAfterRepeatAfterAndThenOnlyAfterAnotherRepeatAfter)
{
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  EXPECT_FALSE(sim.repeatDue(kT0));
  EXPECT_FALSE(sim.repeatDue(kT0 + kRepeatAfter - kNs));
  EXPECT_TRUE(sim.repeatDue(kT0 + kRepeatAfter));
  EXPECT_FALSE(sim.repeatDue(kT0 + kRepeatAfter));
  EXPECT_FALSE(sim.repeatDue(kT0 + 2 * kRepeatAfter - kNs));
  EXPECT_TRUE(sim.repeatDue(kT0 + 2 * kRepeatAfter));
  // A late timer tick: the next repeat is counted from this one.
  const WallClock::time_point late = kT0 + 3 * kRepeatAfter + kRepeatAfter / 2;
  EXPECT_TRUE(sim.repeatDue(late));
  EXPECT_FALSE(sim.repeatDue(late + kRepeatAfter - kNs));
  EXPECT_TRUE(sim.repeatDue(late + kRepeatAfter));
  // A repeat is the same state: same stamp, nothing stepped.
  EXPECT_EQ(tick(1), sim.pending());
  EXPECT_EQ(0u, sim.counts().steps);
  EXPECT_EQ(4u, sim.counts().repeats);
}

TEST(SimProtocol, AStepOrResetRestartsTheRepeatTimerAndADroppedCommandDoesNot)
{
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  const WallClock::time_point stepped = kT0 + kRepeatAfter - kNs;
  ASSERT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(1), stepped));
  EXPECT_FALSE(sim.repeatDue(kT0 + kRepeatAfter));
  // Dropped commands are no answer to the pending state.
  EXPECT_EQ(SimProtocol::Verdict::Duplicate, sim.onCommand(tick(1), stepped + kRepeatAfter / 2));
  EXPECT_EQ(SimProtocol::Verdict::Future, sim.onCommand(tick(9), stepped + kRepeatAfter / 2));
  EXPECT_EQ(SimProtocol::Verdict::Unstamped, sim.onCommand(0, stepped + kRepeatAfter / 2));
  EXPECT_FALSE(sim.repeatDue(stepped + kRepeatAfter - kNs));
  EXPECT_TRUE(sim.repeatDue(stepped + kRepeatAfter));

  const WallClock::time_point reset = stepped + kRepeatAfter + kRepeatAfter / 3;
  sim.onReset(reset);
  EXPECT_FALSE(sim.repeatDue(stepped + 2 * kRepeatAfter));
  EXPECT_FALSE(sim.repeatDue(reset + kRepeatAfter - kNs));
  EXPECT_TRUE(sim.repeatDue(reset + kRepeatAfter));
}

TEST(SimProtocol, SwappedAnswersStepOncePerState)
{
  // The answer to tick 1 is slow, the sim repeats tick 1 and the controller answers the
  // repeat; that answer steps, tick 2 is answered, and the slow first answer comes last.
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  EXPECT_TRUE(sim.repeatDue(kT0 + kRepeatAfter));
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(1), kT0 + kRepeatAfter));
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(2), kT0 + kRepeatAfter));
  EXPECT_EQ(SimProtocol::Verdict::Stale, sim.onCommand(tick(1), kT0 + kRepeatAfter));
  EXPECT_EQ(tick(3), sim.pending());

  // An answer to the next state ahead of the one to the pending state (it cannot be for
  // anything published) is dropped; the pending state's answer steps, and the next state,
  // repeated, is answered again and steps.
  EXPECT_EQ(SimProtocol::Verdict::Future, sim.onCommand(tick(4), kT0 + kRepeatAfter));
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(3), kT0 + kRepeatAfter));
  EXPECT_EQ(tick(4), sim.pending());
  EXPECT_TRUE(sim.repeatDue(kT0 + 2 * kRepeatAfter));
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(tick(4), kT0 + 2 * kRepeatAfter));
  EXPECT_EQ(tick(5), sim.pending());
  EXPECT_EQ(4u, sim.counts().steps);
}

TEST(SimProtocol, TimeNeverGoesBackAcrossResets)
{
  SimProtocol sim(kTick, kRepeatAfter);
  std::vector<Stamp> published{sim.start(kT0)};
  WallClock::time_point now = kT0;
  for (int i = 0; i < 60; ++i)
  {
    now += kRepeatAfter / 4;
    switch (i % 5)
    {
      case 0:
      case 3:
        ASSERT_EQ(SimProtocol::Verdict::Step, sim.onCommand(sim.pending(), now));
        published.push_back(sim.pending());
        break;
      case 1:
        published.push_back(sim.onReset(now));
        break;
      case 2:
        sim.onCommand(published.front(), now);  // dropped, whatever it is
        sim.repeatDue(now + kRepeatAfter);
        break;
      case 4:
        published.push_back(sim.onReset(now));
        published.push_back(sim.onReset(now));
        break;
    }
  }
  for (std::size_t i = 1; i < published.size(); ++i)
    ASSERT_EQ(published[i - 1] + kTick, published[i]) << "state " << i;
  EXPECT_EQ(36u, sim.counts().resets);
}

// --- CommandHold -----------------------------------------------------------------------------

TEST(SimProtocol, AResetThatSetsTimeBackStartsAtTheFirstTickAndAnAnswerInFlightIsStale)
{
  SimProtocol sim(kTick, kRepeatAfter);
  const WallClock::time_point t0 = WallClock::now();
  sim.start(t0);
  for (int i = 0; i < 5; ++i)
    sim.onCommand(sim.pending(), t0);
  const Stamp before = sim.pending();
  EXPECT_EQ(kTick, sim.onResetTimeBack(t0));
  EXPECT_EQ(1u, sim.counts().resets);
  EXPECT_EQ(SimProtocol::Verdict::Future, sim.onCommand(before, t0));  // answers a state of the old time
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(kTick, t0));
}

TEST(CommandHold, ZeroBeforeAnyCommand)
{
  const CommandHold hold(std::chrono::milliseconds(500));
  EXPECT_EQ(0.0, hold.effort(kT0));
  EXPECT_EQ(0.0, hold.effort(kT0 + std::chrono::hours(1)));
}

TEST(CommandHold, HeldWhileFreshAndZeroAfterTheTimeout)
{
  const WallClock::duration timeout = std::chrono::milliseconds(500);
  CommandHold hold(timeout);
  ASSERT_TRUE(hold.set(3.5, tick(1), kT0));
  EXPECT_EQ(3.5, hold.effort(kT0));
  EXPECT_EQ(3.5, hold.effort(kT0 + timeout));
  EXPECT_EQ(0.0, hold.effort(kT0 + timeout + kNs));
  // A new command is held afresh.
  ASSERT_TRUE(hold.set(-2.0, tick(2), kT0 + 2 * timeout));
  EXPECT_EQ(-2.0, hold.effort(kT0 + 3 * timeout));
  EXPECT_EQ(0.0, hold.effort(kT0 + 3 * timeout + kNs));
}

TEST(CommandHold, AnOlderStampedCommandIsRefusedAndDoesNotRefreshTheHold)
{
  const WallClock::duration timeout = std::chrono::milliseconds(500);
  CommandHold hold(timeout);
  ASSERT_TRUE(hold.set(1.0, tick(5), kT0));
  EXPECT_FALSE(hold.set(-1.0, tick(4), kT0 + timeout / 2));
  EXPECT_EQ(1.0, hold.effort(kT0 + timeout / 2));
  EXPECT_EQ(0.0, hold.effort(kT0 + timeout + kNs));
  EXPECT_TRUE(hold.set(4.0, tick(6), kT0 + timeout));
  EXPECT_EQ(4.0, hold.effort(kT0 + timeout));
}

TEST(CommandHold, StampZeroIsAlwaysAccepted)
{
  const WallClock::duration timeout = std::chrono::milliseconds(500);
  CommandHold hold(timeout);
  EXPECT_TRUE(hold.set(2.0, 0, kT0));
  EXPECT_EQ(2.0, hold.effort(kT0));
  ASSERT_TRUE(hold.set(1.0, tick(9), kT0));
  EXPECT_TRUE(hold.set(-3.0, 0, kT0 + timeout));
  EXPECT_EQ(-3.0, hold.effort(kT0 + 2 * timeout));  // and it refreshes the hold
  EXPECT_TRUE(hold.set(5.0, 0, kT0 + 2 * timeout));
  EXPECT_EQ(5.0, hold.effort(kT0 + 2 * timeout));
}

// --- ControllerProtocol ----------------------------------------------------------------------

class ControllerProtocolTest : public ::testing::Test
{
protected:
  std::uint64_t learntSteps() const
  {
    return session_.table().steps;
  }

  // The session as the controller node builds it: the shipped task and agent.
  TrainingConfig config_ = shippedConfig();
  TrainingSession session_{config_.task, config_.agent, 0};
  ControllerProtocolParams params_;
};

TEST_F(ControllerProtocolTest, TheFirstStateBeginsAnEpisodeAndIsAnsweredWithItsStamp)
{
  ControllerProtocol controller(session_, params_);
  const Reaction r = controller.onState(tick(1), kUpright);
  EXPECT_EQ(Reaction::Kind::New, r.kind);
  EXPECT_TRUE(r.episode_began);
  EXPECT_TRUE(r.answer);
  EXPECT_EQ(tick(1), r.stamp);
  EXPECT_TRUE(r.effort == -10.0 || r.effort == 10.0) << r.effort;
  EXPECT_FALSE(r.learned);
  EXPECT_FALSE(r.request_reset);
  EXPECT_FALSE(r.first_unstamped);
  EXPECT_TRUE(session_.inEpisode());
  EXPECT_EQ(0u, learntSteps());
  EXPECT_EQ(ControllerProtocol::Phase::InEpisode, controller.phase());
}

TEST_F(ControllerProtocolTest, ANewStampIsLearntFromExactlyOnceAndAnswered)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  for (std::uint64_t n = 2; n <= 6; ++n)
  {
    const std::uint64_t before = learntSteps();
    const Reaction r = controller.onState(tick(n), kSmall);
    EXPECT_EQ(Reaction::Kind::New, r.kind);
    EXPECT_TRUE(r.learned);
    EXPECT_TRUE(r.answer);
    EXPECT_FALSE(r.episode_began);
    EXPECT_EQ(tick(n), r.stamp);
    EXPECT_EQ(before + 1, learntSteps());
  }
  EXPECT_EQ(6u, controller.counts().states);
}

TEST_F(ControllerProtocolTest, ARepeatIsAnsweredAgainWithTheSameEffortAndStampAndLearnsNothing)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  for (std::uint64_t n = 2; n <= 5; ++n)
  {
    const Reaction first = controller.onState(tick(n), kSmall);
    ASSERT_TRUE(first.answer);
    const std::vector<double> values = session_.table().values();
    const std::uint64_t before = learntSteps();
    // Several repeats: were each a new decision, an exploring agent would not keep the effort.
    for (int repeat = 0; repeat < 8; ++repeat)
    {
      const Reaction r = controller.onState(tick(n), kSmall);
      EXPECT_EQ(Reaction::Kind::Repeat, r.kind);
      EXPECT_TRUE(r.answer);
      EXPECT_EQ(first.effort, r.effort);
      EXPECT_EQ(tick(n), r.stamp);
      EXPECT_FALSE(r.learned);
      EXPECT_FALSE(r.episode_began);
    }
    EXPECT_EQ(before, learntSteps());
    EXPECT_TRUE(bitIdentical(values, session_.table().values()));
  }
  EXPECT_EQ(32u, controller.counts().repeats);
  EXPECT_EQ(5u, controller.counts().states);
}

TEST_F(ControllerProtocolTest, AfterALostStateTheNextStampIsStillNew)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  controller.onState(tick(2), kSmall);
  const std::uint64_t before = learntSteps();
  const Reaction r = controller.onState(tick(4), kSmall);
  EXPECT_EQ(Reaction::Kind::New, r.kind);
  EXPECT_TRUE(r.learned);
  EXPECT_TRUE(r.answer);
  EXPECT_EQ(tick(4), r.stamp);
  EXPECT_EQ(before + 1, learntSteps());
  // The lost state, delivered late, is older than the last.
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(3), kSmall).kind);
}

TEST_F(ControllerProtocolTest, AnOlderStampSeenOnceIsDroppedWithoutLearning)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  controller.onState(tick(2), kSmall);
  controller.onState(tick(3), kSmall);
  const std::uint64_t before = learntSteps();
  const std::vector<double> values = session_.table().values();

  const Reaction r = controller.onState(tick(1), kSmall);
  EXPECT_EQ(Reaction::Kind::Stale, r.kind);
  EXPECT_FALSE(r.answer);
  EXPECT_FALSE(r.learned);
  EXPECT_FALSE(r.sim_restarted);
  EXPECT_EQ(before, learntSteps());
  EXPECT_TRUE(bitIdentical(values, session_.table().values()));
  EXPECT_EQ(1u, controller.counts().stale);
  // The episode goes on: the next state is learnt from.
  EXPECT_TRUE(session_.inEpisode());
  const Reaction next = controller.onState(tick(4), kSmall);
  EXPECT_TRUE(next.learned);
  EXPECT_FALSE(next.episode_began);
  EXPECT_EQ(before + 1, learntSteps());
  // Two different older stamps, once each, are no restart; nor is an older stamp again after a
  // new state came between (a second late copy: the sim that sent the new state is alive).
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(2), kSmall).kind);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(3), kSmall).kind);
  controller.onState(tick(5), kSmall);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(3), kSmall).kind);
  EXPECT_EQ(0u, controller.counts().restarts);
  EXPECT_EQ(4u, controller.counts().stale);
}

TEST_F(ControllerProtocolTest, TheSameOlderStampTwiceIsASimRestartThatAbandonsTheEpisode)
{
  ControllerProtocol controller(session_, params_);
  // One whole episode, then one under way.
  controller.onState(tick(1), kUpright);
  controller.onState(tick(2), kFallen);
  ASSERT_EQ(1u, session_.episodesEnded());
  controller.onState(tick(3), kUpright);
  for (std::uint64_t n = 4; n <= 9; ++n)
    controller.onState(tick(n), kSmall);
  ASSERT_TRUE(session_.inEpisode());
  const std::uint64_t before = learntSteps();

  // The restarted sim publishes its first state, and repeats it while nobody answers.
  const Reaction stale = controller.onState(tick(1), kUpright);
  EXPECT_EQ(Reaction::Kind::Stale, stale.kind);
  EXPECT_FALSE(stale.answer);
  const Reaction r = controller.onState(tick(1), kUpright);
  EXPECT_TRUE(r.sim_restarted);
  EXPECT_EQ(Reaction::Kind::New, r.kind);
  EXPECT_TRUE(r.episode_began);
  EXPECT_TRUE(r.answer);
  EXPECT_EQ(tick(1), r.stamp);
  EXPECT_FALSE(r.learned);
  EXPECT_FALSE(r.episode_ended);
  EXPECT_EQ(before, learntSteps());
  EXPECT_EQ(1u, session_.episodesEnded());
  EXPECT_EQ(1u, session_.table().episodes);
  EXPECT_TRUE(session_.inEpisode());
  EXPECT_EQ(1u, controller.counts().restarts);

  // The new sim's states are new from its first on, and the episode counts from the restart.
  const Reaction second = controller.onState(tick(2), kSmall);
  EXPECT_EQ(Reaction::Kind::New, second.kind);
  EXPECT_TRUE(second.learned);
  EXPECT_TRUE(second.answer);
  EXPECT_EQ(Reaction::Kind::Repeat, controller.onState(tick(2), kSmall).kind);
  const Reaction fall = controller.onState(tick(3), kFallen);
  EXPECT_TRUE(fall.episode_ended);
  EXPECT_EQ(2u, session_.episodesEnded());
  EXPECT_EQ(2u, session_.lastEpisode().steps);
}

TEST_F(ControllerProtocolTest, TimeSetBackAndGoingOnIsARestartOnItsThirdState)
{
  // Gazebo's reset_simulation: the states after it start near 0 and go on from there.
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(100), kUpright);
  for (std::uint64_t n = 101; n <= 110; ++n)
    controller.onState(tick(n), kSmall);
  ASSERT_TRUE(session_.inEpisode());
  const std::uint64_t before = learntSteps();
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(1), kUpright).kind);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(2), kUpright).kind);
  const Reaction r = controller.onState(tick(3), kUpright);
  EXPECT_TRUE(r.sim_restarted);
  EXPECT_TRUE(r.episode_began);
  EXPECT_TRUE(r.answer);
  EXPECT_FALSE(r.learned);
  EXPECT_EQ(before, learntSteps());
  EXPECT_EQ(0u, session_.episodesEnded());  // the abandoned episode is not counted
  // Training goes on at the new time.
  const Reaction next = controller.onState(tick(4), kSmall);
  EXPECT_EQ(Reaction::Kind::New, next.kind);
  EXPECT_TRUE(next.learned);
  EXPECT_EQ(before + 1, learntSteps());
  // Older states that do not go on in order (replays) stay dropped.
  controller.onState(tick(10), kSmall);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(6), kSmall).kind);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(5), kSmall).kind);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(7), kSmall).kind);
  EXPECT_EQ(1u, controller.counts().restarts);
}

TEST_F(ControllerProtocolTest, InControlTimeSetBackWithThePoleUpGoesOnBalancingAndWithThePoleDownWaits)
{
  // A table driving a robot (greedy, no learning): the robot's clock steps back an hour.
  TrainingSession greedy(config_.task, config_.agent, 0, false);
  params_.time_back_judged_by_state = true;
  params_.reset_service = false;
  ControllerProtocol controller(greedy, params_);
  const Stamp hour = 3600ULL * 1000000000ULL;
  controller.onState(hour + tick(1), kUpright);
  for (std::uint64_t n = 2; n <= 10; ++n)
    controller.onState(hour + tick(n), kSmall);
  ASSERT_TRUE(greedy.inEpisode());
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(1), kSmall).kind);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(2), kSmall).kind);
  const Reaction r = controller.onState(tick(3), kSmall);
  EXPECT_TRUE(r.clock_set_back);
  EXPECT_FALSE(r.sim_restarted);
  EXPECT_FALSE(r.episode_began);
  EXPECT_FALSE(r.episode_ended);
  EXPECT_TRUE(r.answer);
  EXPECT_EQ(tick(3), r.stamp);
  EXPECT_TRUE(greedy.inEpisode());
  EXPECT_EQ(0u, greedy.episodesEnded());
  EXPECT_EQ(ControllerProtocol::Phase::InEpisode, controller.phase());
  const Reaction next = controller.onState(tick(4), kSmall);
  EXPECT_EQ(Reaction::Kind::New, next.kind);
  EXPECT_TRUE(next.answer);

  // The same with the pole down when time goes back: that stretch is over, and a start is waited for.
  const Stamp later = 2 * hour;
  controller.onState(later, kSmall);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(1), kFallen).kind);
  EXPECT_EQ(Reaction::Kind::Stale, controller.onState(tick(2), kFallen).kind);
  const Reaction down = controller.onState(tick(3), kFallen);
  EXPECT_TRUE(down.sim_restarted);
  EXPECT_FALSE(down.clock_set_back);
  EXPECT_EQ(0.0, down.effort);
}

TEST_F(ControllerProtocolTest, AStampZeroAmidStampedStatesIsAStray)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  const Reaction answered = controller.onState(tick(2), kSmall);
  const std::uint64_t before = learntSteps();
  const Reaction r = controller.onState(0, kSmall);
  EXPECT_EQ(Reaction::Kind::Stray, r.kind);
  EXPECT_FALSE(r.answer);
  EXPECT_FALSE(r.learned);
  EXPECT_FALSE(r.first_unstamped);
  EXPECT_EQ(before, learntSteps());
  EXPECT_EQ(1u, controller.counts().stray);
  // The stamped stream goes on as before it.
  const Reaction repeat = controller.onState(tick(2), kSmall);
  EXPECT_EQ(Reaction::Kind::Repeat, repeat.kind);
  EXPECT_EQ(answered.effort, repeat.effort);
  EXPECT_TRUE(controller.onState(tick(3), kSmall).learned);
}

TEST_F(ControllerProtocolTest, AStreamWithoutStampsIsServedEachMessageANewState)
{
  ControllerProtocol controller(session_, params_);
  const Reaction first = controller.onState(0, kUpright);
  EXPECT_EQ(Reaction::Kind::New, first.kind);
  EXPECT_TRUE(first.first_unstamped);
  EXPECT_TRUE(first.episode_began);
  EXPECT_TRUE(first.answer);
  EXPECT_EQ(0u, first.stamp);
  for (int i = 1; i <= 5; ++i)
  {
    // The same values each time: without a stamp, a message cannot be told to be a repeat.
    const std::uint64_t before = learntSteps();
    const Reaction r = controller.onState(0, kUpright);
    EXPECT_EQ(Reaction::Kind::New, r.kind);
    EXPECT_FALSE(r.first_unstamped);
    EXPECT_TRUE(r.learned);
    EXPECT_TRUE(r.answer);
    EXPECT_EQ(0u, r.stamp);
    EXPECT_EQ(before + 1, learntSteps());
  }
  EXPECT_EQ(0u, controller.counts().stray);
  EXPECT_EQ(6u, controller.counts().states);
}

TEST_F(ControllerProtocolTest, AFallRequestsAResetAndOnlyANonTerminalNewStateBeginsTheNextEpisode)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  controller.onState(tick(2), kSmall);
  const std::uint64_t before = learntSteps();
  const Reaction fall = controller.onState(tick(3), kFallen);
  EXPECT_TRUE(fall.episode_ended);
  EXPECT_TRUE(fall.learned);
  EXPECT_TRUE(fall.request_reset);
  EXPECT_FALSE(fall.answer);
  EXPECT_FALSE(fall.training_finished);
  EXPECT_EQ(before + 1, learntSteps());
  EXPECT_EQ(1u, session_.episodesEnded());
  EXPECT_TRUE(session_.lastEpisode().terminated);
  EXPECT_EQ(2u, session_.lastEpisode().steps);
  EXPECT_EQ(ControllerProtocol::Phase::AwaitingReset, controller.phase());

  // The fallen state repeated while the reset is on its way: no answer, nothing learnt.
  for (int i = 0; i < 3; ++i)
  {
    const Reaction r = controller.onState(tick(3), kFallen);
    EXPECT_EQ(Reaction::Kind::Repeat, r.kind);
    EXPECT_FALSE(r.answer);
    EXPECT_FALSE(r.learned);
  }
  // Realtime: the sim steps on before the reset is served.
  const Reaction past = controller.onState(tick(4), kFallen);
  EXPECT_EQ(Reaction::Kind::New, past.kind);
  EXPECT_FALSE(past.answer);
  EXPECT_FALSE(past.learned);
  EXPECT_FALSE(past.episode_began);
  EXPECT_FALSE(past.episode_ended);
  EXPECT_EQ(before + 1, learntSteps());
  EXPECT_EQ(1u, session_.episodesEnded());

  const Reaction start = controller.onState(tick(5), kUpright);
  EXPECT_TRUE(start.episode_began);
  EXPECT_TRUE(start.answer);
  EXPECT_EQ(tick(5), start.stamp);
  EXPECT_FALSE(start.learned);
  EXPECT_EQ(before + 1, learntSteps());
  EXPECT_TRUE(controller.onState(tick(6), kSmall).learned);
  EXPECT_EQ(before + 2, learntSteps());
}

TEST_F(ControllerProtocolTest, AStartDrawnPastTheFallInAWideStartRegionIsAnEpisodeOfOneStep)
{
  // config/robust.yaml draws starts in +-0.25 rad, past the fall at 12 degrees (0.2094 rad):
  // train_headless begins such an episode and learns from its one step, and the lockstep sim
  // waits for an answer to it. Only inside the start region: a pole past it is still falling.
  params_.start_region = CartPoleState::Constant(0.25);
  ControllerProtocol controller(session_, params_);
  const CartPoleState fallen_start(0.1, -0.2, 0.22, 0.15);
  ASSERT_TRUE(session_.task().isTerminal(fallen_start));
  const Reaction first = controller.onState(tick(1), fallen_start);
  EXPECT_TRUE(first.episode_began);
  EXPECT_TRUE(first.answer);
  EXPECT_FALSE(first.request_reset);
  const Reaction fall = controller.onState(tick(2), CartPoleState(0.1, -0.1, 0.225, 0.4));
  EXPECT_TRUE(fall.episode_ended);
  EXPECT_TRUE(fall.request_reset);
  EXPECT_EQ(1u, session_.lastEpisode().steps);
  EXPECT_EQ(1u, learntSteps());

  // After the reset, another start past the fall: answered again, not waited on.
  const Reaction again = controller.onState(tick(3), CartPoleState(-0.05, 0.0, -0.24, 0.1));
  EXPECT_TRUE(again.episode_began);
  EXPECT_TRUE(again.answer);
  // A pole fallen beyond the region (a realtime sim stepping on before its reset is served)
  // still begins nothing.
  ASSERT_TRUE(controller.onState(tick(4), CartPoleState(0.0, 0.0, -0.3, -1.0)).request_reset);
  const Reaction falling = controller.onState(tick(5), CartPoleState(0.0, 0.0, -0.35, -1.2));
  EXPECT_FALSE(falling.episode_began);
  EXPECT_FALSE(falling.answer);
  EXPECT_TRUE(controller.onState(tick(6), kUpright).episode_began);
}

TEST_F(ControllerProtocolTest, AControllerRestartedMidRunAnswersTheSimsPendingState)
{
  SimProtocol sim(kTick, kRepeatAfter);
  sim.start(kT0);
  for (int i = 0; i < 56; ++i)
    sim.onUnstampedCommand(kT0);
  ASSERT_EQ(tick(57), sim.pending());

  // A fresh controller and session, as after a respawn, given the sim's repeat of its state.
  TrainingSession session(config_.task, config_.agent, 3);
  ControllerProtocol controller(session, params_);
  const Reaction r = controller.onState(sim.pending(), kSmall);
  EXPECT_EQ(Reaction::Kind::New, r.kind);
  EXPECT_TRUE(r.episode_began);
  EXPECT_TRUE(r.answer);
  EXPECT_EQ(tick(57), r.stamp);
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(r.stamp, kT0));
  const Reaction next = controller.onState(sim.pending(), kSmall);
  EXPECT_TRUE(next.learned);
  EXPECT_EQ(SimProtocol::Verdict::Step, sim.onCommand(next.stamp, kT0));
}

TEST_F(ControllerProtocolTest, AfterAResetThatSaysNothingTheEpisodeStartsInsideTheStartRegion)
{
  // std_srvs/Empty (Gazebo): the state after the reset may still move; it is answered with 0
  // until it is inside the start region.
  params_.reset_starts_in_region = true;
  params_.start_region = CartPoleState::Constant(0.05);
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  const Reaction moving = controller.onState(tick(3), CartPoleState(0.0, 0.5, 0.0, 0.0));
  EXPECT_FALSE(moving.episode_began);
  EXPECT_TRUE(moving.answer);
  EXPECT_EQ(0.0, moving.effort);
  EXPECT_FALSE(controller.onState(tick(4), kFallen).episode_began);
  const Reaction still = controller.onState(tick(5), CartPoleState(0.0, 0.01, 0.0, 0.0));
  EXPECT_TRUE(still.episode_began);
  EXPECT_EQ(ControllerProtocol::Phase::InEpisode, controller.phase());
}

// A pole spinning round after a fall: it passes upright (not fallen by the task's thresholds)
// fast, so never inside the start region.
CartPoleState spinning(std::uint64_t n)
{
  return CartPoleState(0.02, 0.01, n % 3 == 0 ? 0.0 : (n % 3 == 1 ? 0.15 : 2.5), 9.0);
}

TEST_F(ControllerProtocolTest, AfterAFailedResetSpinningStatesStartNoEpisodeUntilTheStateIsInTheStartRegion)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  EXPECT_FALSE(controller.onState(tick(2), kFallen).answer) << "the lockstep sim's repeat of its fallen state";
  controller.onResetOutcome(false);
  EXPECT_FALSE(controller.onState(tick(2), kFallen).answer) << "nor after the failure: the sim waits on it";
  const std::uint64_t learnt = learntSteps();
  for (std::uint64_t n = 3; n < 60; ++n)
  {
    const Reaction r = controller.onState(tick(n), spinning(n));
    EXPECT_EQ(Reaction::Kind::New, r.kind);
    EXPECT_FALSE(r.episode_began) << n;
    EXPECT_FALSE(r.learned);
    EXPECT_FALSE(r.request_reset) << "the reset caller retries the one asked for";
    EXPECT_FALSE(r.waiting_for_start) << "said by the reset caller, not as a robot without a reset service";
    EXPECT_TRUE(r.answer) << "commanded 0, as a robot without a reset service";
    EXPECT_EQ(0.0, r.effort);
  }
  // A repeat is not answered: a lockstep sim's fallen state, repeated, would be stepped on flat
  // out for as long as no reset works.
  const Reaction repeat = controller.onState(tick(59), spinning(59));
  EXPECT_EQ(Reaction::Kind::Repeat, repeat.kind);
  EXPECT_FALSE(repeat.answer);
  EXPECT_EQ(1u, session_.episodesEnded());
  EXPECT_EQ(learnt, learntSteps());
  EXPECT_EQ(ControllerProtocol::Phase::WaitingForPerson, controller.phase());

  // Back inside the start region (stood up by hand): an episode as without a reset service.
  const Reaction start = controller.onState(tick(60), kSmall);
  EXPECT_TRUE(start.episode_began);
  EXPECT_TRUE(start.answer);
  // Its end asks for a reset again; while none has succeeded, the same rule holds.
  ASSERT_TRUE(controller.onState(tick(61), kFallen).request_reset);
  EXPECT_EQ(2u, session_.episodesEnded());
  EXPECT_FALSE(controller.onState(tick(62), spinning(0)).episode_began);
  EXPECT_FALSE(controller.onState(tick(63), kLeaning).episode_began) << "not fallen, but outside the region";
  EXPECT_TRUE(controller.onState(tick(64), kUpright).episode_began);
}

TEST_F(ControllerProtocolTest, AResetThatFailsThenSucceedsStartsTheEpisodeOnTheResetsState)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  controller.onResetOutcome(false);
  EXPECT_FALSE(controller.onState(tick(3), spinning(3)).episode_began);
  EXPECT_FALSE(controller.onState(tick(4), kLeaning).episode_began);
  // The retry succeeds, and its answer comes first: the rule of a working reset is back, a state
  // that is not fallen starts the episode (a start outside a narrow start region included).
  controller.onResetOutcome(true);
  EXPECT_EQ(ControllerProtocol::Phase::AwaitingReset, controller.phase());
  const Reaction fallen = controller.onState(tick(5), kFallen);
  EXPECT_FALSE(fallen.episode_began) << "a fallen state still in flight";
  EXPECT_FALSE(fallen.answer);
  const Reaction start = controller.onState(tick(6), kLeaning);
  EXPECT_TRUE(start.episode_began);
  EXPECT_TRUE(start.answer);
  EXPECT_EQ(1u, session_.episodesEnded());
}

TEST_F(ControllerProtocolTest, AResetsStateBeforeItsSuccessfulAnswerStartsTheEpisodeEitherWay)
{
  // The retry's reset publishes its state before its answer comes back. Inside the start region:
  // the episode starts on it, and the answer after it changes nothing.
  {
    TrainingSession session(config_.task, config_.agent, 0);
    ControllerProtocol controller(session, params_);
    controller.onState(tick(1), kUpright);
    controller.onState(tick(2), kFallen);
    controller.onResetOutcome(false);
    EXPECT_TRUE(controller.onState(tick(3), kSmall).episode_began);
    controller.onResetOutcome(true);
    EXPECT_EQ(ControllerProtocol::Phase::InEpisode, controller.phase());
    EXPECT_TRUE(controller.onState(tick(4), kSmall).learned);
  }
  // Outside it (a sim drawing starts wider than ~start_region): answered with 0, and the state
  // after the answer starts the episode.
  {
    TrainingSession session(config_.task, config_.agent, 0);
    ControllerProtocol controller(session, params_);
    controller.onState(tick(1), kUpright);
    controller.onState(tick(2), kFallen);
    controller.onResetOutcome(false);
    const Reaction early = controller.onState(tick(3), kLeaning);
    EXPECT_FALSE(early.episode_began);
    EXPECT_TRUE(early.answer);
    EXPECT_EQ(0.0, early.effort);
    controller.onResetOutcome(true);
    EXPECT_TRUE(controller.onState(tick(4), kLeaning).episode_began);
  }
}

TEST_F(ControllerProtocolTest, AFallAfterTheResetWasServedThatTheSimWaitsOnAsksForAnotherReset)
{
  // bad_messages.test's flood: the reset was served, then a hand on cart_effort stepped the sim
  // on until its pole fell, before the controller saw the reset's start. The lockstep sim repeats
  // that fallen state, unanswered; the controller asks for a reset again at its second repeat.
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  for (int i = 0; i < 5; ++i)  // the sim's repeats while the reset call is under way: nothing
    EXPECT_FALSE(controller.onState(tick(2), kFallen).request_reset) << "before its answer " << i;
  controller.onResetOutcome(true);
  const Reaction moved_on = controller.onState(tick(9), kFallen);
  EXPECT_EQ(Reaction::Kind::New, moved_on.kind);
  EXPECT_FALSE(moved_on.request_reset) << "a fall may still be in flight";
  EXPECT_FALSE(moved_on.answer);
  const Reaction first = controller.onState(tick(9), kFallen);
  EXPECT_FALSE(first.request_reset) << "the first repeat may have been sent before the reset";
  const Reaction second = controller.onState(tick(9), kFallen);
  EXPECT_EQ(Reaction::Kind::Repeat, second.kind);
  EXPECT_TRUE(second.request_reset);
  EXPECT_FALSE(second.answer);
  EXPECT_EQ(ControllerProtocol::Phase::AwaitingReset, controller.phase());
  EXPECT_FALSE(controller.onState(tick(9), kFallen).request_reset) << "once per reset served";
  controller.onResetOutcome(true);
  EXPECT_TRUE(controller.onState(tick(10), kSmall).episode_began);
  EXPECT_EQ(1u, session_.episodesEnded());
}

TEST_F(ControllerProtocolTest, TheFallThatAskedForTheResetRepeatedUntilItWasServedAsksForNoOther)
{
  // The controller judges the table at the episode's end before it calls the reset: a whole
  // verdict takes seconds on a loaded machine (Debian 11's root, load 7), and the lockstep sim
  // repeats its fallen state every half second meanwhile. Those repeats are read after the
  // reset's answer. Asking again there reset the sim twice: the next start was another draw, and
  // train.launch's table was no longer train_headless's (robust_train.test).
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  controller.onResetOutcome(true);
  for (int i = 0; i < 6; ++i)
  {
    const Reaction queued = controller.onState(tick(2), kFallen);
    EXPECT_EQ(Reaction::Kind::Repeat, queued.kind);
    EXPECT_FALSE(queued.request_reset) << "repeat " << i << " of the fall that asked for the reset";
    EXPECT_FALSE(queued.answer);
  }
  EXPECT_TRUE(controller.onState(tick(3), kSmall).episode_began) << "the reset's start";
  EXPECT_EQ(1u, session_.episodesEnded());
}

TEST_F(ControllerProtocolTest, ARealtimeRobotFelledAfterItsResetWasServedIsResetAgainAfterFiftyFallenStates)
{
  // Realtime: the felled robot sends new states, each fallen. Before the reset's answer none of
  // them asks again (the sim falls on until it is reset); after it, the 50th does.
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  std::uint64_t n = 3;
  for (int i = 0; i < 100; ++i, ++n)
    EXPECT_FALSE(controller.onState(tick(n), kFallen).request_reset) << "before the reset's answer " << i;
  controller.onResetOutcome(true);
  for (int i = 1; i < 50; ++i, ++n)
  {
    const Reaction r = controller.onState(tick(n), kFallen);
    EXPECT_FALSE(r.request_reset) << i;
    EXPECT_FALSE(r.answer) << i;
  }
  EXPECT_TRUE(controller.onState(tick(n++), kFallen).request_reset);
  for (int i = 0; i < 100; ++i, ++n)
    EXPECT_FALSE(controller.onState(tick(n), kFallen).request_reset) << "once per reset served " << i;
  controller.onResetOutcome(true);
  EXPECT_TRUE(controller.onState(tick(n++), kSmall).episode_began);
  EXPECT_EQ(1u, session_.episodesEnded());
}

TEST_F(ControllerProtocolTest, WorkingResetsAndOutcomesWithoutAResetServiceChangeNothing)
{
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  ASSERT_TRUE(controller.onState(tick(2), kFallen).request_reset);
  controller.onResetOutcome(true);
  EXPECT_FALSE(controller.onState(tick(2), kFallen).answer) << "a repeat while awaiting the reset";
  EXPECT_TRUE(controller.onState(tick(3), kLeaning).episode_began);

  params_.reset_service = false;
  TrainingSession session(config_.task, config_.agent, 0);
  ControllerProtocol robot(session, params_);
  robot.onResetOutcome(false);
  EXPECT_TRUE(robot.onState(tick(1), kUpright).episode_began);
  robot.onState(tick(2), kFallen);
  EXPECT_TRUE(robot.onState(tick(3), kFallen).answer);
  EXPECT_TRUE(robot.onState(tick(3), kFallen).answer) << "a repeat, as a robot without a reset service has it";
  robot.onResetOutcome(true);
  EXPECT_EQ(ControllerProtocol::Phase::WaitingForPerson, robot.phase());
}

TEST_F(ControllerProtocolTest, AFirstStateThatIsTerminalRequestsAResetWithoutLearning)
{
  ControllerProtocol controller(session_, params_);
  const Reaction r = controller.onState(tick(7), kFallen);
  EXPECT_EQ(Reaction::Kind::New, r.kind);
  EXPECT_TRUE(r.request_reset);
  EXPECT_FALSE(r.answer);
  EXPECT_FALSE(r.learned);
  EXPECT_FALSE(r.episode_began);
  EXPECT_FALSE(r.episode_ended);
  EXPECT_FALSE(session_.inEpisode());
  EXPECT_EQ(0u, learntSteps());
  EXPECT_EQ(0u, session_.episodesEnded());
  EXPECT_FALSE(controller.onState(tick(7), kFallen).answer);

  const Reaction start = controller.onState(tick(8), kUpright);
  EXPECT_TRUE(start.episode_began);
  EXPECT_TRUE(start.answer);
  EXPECT_EQ(0u, learntSteps());
}

TEST_F(ControllerProtocolTest, AGreedyTableWithoutAResetStartsWhenThePoleIsUpAndGoesOnPastAStepLimit)
{
  // Evaluation on a robot with no reset: 3-step episodes, noisy readings outside the start region.
  TaskParams task = config_.task;
  task.max_episode_steps = 3;
  TrainingSession greedy(task, config_.agent, 0, false);
  params_.reset_service = false;
  params_.starts_when_up = true;
  ControllerProtocol controller(greedy, params_);
  // Leaning 0.1 rad (outside the 0.05 start region, inside the 12-degree threshold): up.
  EXPECT_TRUE(controller.onState(tick(1), kLeaning).episode_began);
  controller.onState(tick(2), kLeaning);
  controller.onState(tick(3), kLeaning);
  // The step limit with the pole up: this episode ends and the next begins on the same state,
  // answered with the table's effort, not 0.
  const Reaction limit = controller.onState(tick(4), kLeaning);
  EXPECT_TRUE(limit.episode_ended);
  EXPECT_TRUE(limit.episode_began);
  EXPECT_FALSE(limit.waiting_for_start);
  EXPECT_TRUE(limit.answer);
  EXPECT_NE(0.0, limit.effort);
  EXPECT_TRUE(greedy.lastEpisode().truncated);
  EXPECT_EQ(1u, greedy.episodesEnded());
  // A fall: 0 until the pole is up again by the thresholds, whatever the start region says.
  const Reaction fall = controller.onState(tick(5), kFallen);
  EXPECT_TRUE(fall.episode_ended);
  EXPECT_TRUE(fall.waiting_for_start);
  EXPECT_TRUE(fall.waiting_for_pole_up);
  EXPECT_EQ(0.0, fall.effort);
  EXPECT_EQ(0.0, controller.onState(tick(6), kFallen).effort);
  const Reaction up = controller.onState(tick(7), kLeaning);
  EXPECT_TRUE(up.episode_began);
  EXPECT_EQ(2u, greedy.episodesEnded());
}

TEST_F(ControllerProtocolTest, WithoutAResetServiceItCommandsZeroUntilTheStateIsInTheStartRegion)
{
  params_.reset_service = false;
  ControllerProtocol controller(session_, params_);
  ASSERT_TRUE(controller.onState(tick(1), kUpright).episode_began);
  controller.onState(tick(2), kSmall);
  const Reaction fall = controller.onState(tick(3), kFallen);
  EXPECT_TRUE(fall.episode_ended);
  EXPECT_TRUE(fall.learned);
  EXPECT_FALSE(fall.request_reset);
  EXPECT_TRUE(fall.waiting_for_start);
  EXPECT_TRUE(fall.answer);
  EXPECT_EQ(0.0, fall.effort);
  EXPECT_EQ(tick(3), fall.stamp);
  const std::uint64_t before = learntSteps();

  // A person stands the pole up: fallen, then leaning, then upright.
  const std::vector<CartPoleState> gap{kFallen, kLeaning, leaning(-0.2), CartPoleState(0.3, 0.0, 0.0, 0.0)};
  std::uint64_t n = 4;
  for (const CartPoleState& state : gap)
  {
    const Reaction r = controller.onState(tick(n), state);
    EXPECT_EQ(Reaction::Kind::New, r.kind);
    EXPECT_TRUE(r.answer);
    EXPECT_EQ(0.0, r.effort);
    EXPECT_EQ(tick(n), r.stamp);
    EXPECT_FALSE(r.waiting_for_start);  // said once per gap
    EXPECT_FALSE(r.learned);
    EXPECT_FALSE(r.episode_began);
    EXPECT_FALSE(r.request_reset);
    const Reaction repeat = controller.onState(tick(n), state);
    EXPECT_TRUE(repeat.answer);
    EXPECT_EQ(0.0, repeat.effort);
    ++n;
  }
  EXPECT_EQ(before, learntSteps());
  EXPECT_EQ(1u, session_.episodesEnded());

  const Reaction start = controller.onState(tick(n), kSmall);
  EXPECT_TRUE(start.episode_began);
  EXPECT_TRUE(start.answer);
  EXPECT_FALSE(start.learned);
  EXPECT_EQ(before, learntSteps());
  EXPECT_TRUE(controller.onState(tick(n + 1), kSmall).learned);
  EXPECT_EQ(before + 1, learntSteps());
}

TEST_F(ControllerProtocolTest, WithoutAResetServiceAFirstStateOutsideTheStartRegionWaits)
{
  params_.reset_service = false;
  ControllerProtocol controller(session_, params_);
  const Reaction r = controller.onState(tick(1), kLeaning);
  EXPECT_TRUE(r.waiting_for_start);
  EXPECT_TRUE(r.answer);
  EXPECT_EQ(0.0, r.effort);
  EXPECT_FALSE(r.episode_began);
  EXPECT_FALSE(r.request_reset);
  EXPECT_FALSE(controller.onState(tick(2), kFallen).waiting_for_start);
  EXPECT_TRUE(controller.onState(tick(3), kUpright).episode_began);
}

TEST_F(ControllerProtocolTest, TrainingEndsAfterTheEpisodeThatReachesTheLimits)
{
  params_.limits.max_episodes = 2;
  params_.limits.stop_when_solved = false;
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  const Reaction first = controller.onState(tick(2), kFallen);
  EXPECT_TRUE(first.episode_ended);
  EXPECT_FALSE(first.training_finished);
  EXPECT_TRUE(first.request_reset);
  controller.onState(tick(3), kUpright);
  controller.onState(tick(4), kSmall);
  const Reaction last = controller.onState(tick(5), kFallen);
  EXPECT_TRUE(last.episode_ended);
  EXPECT_TRUE(last.learned);
  EXPECT_TRUE(last.training_finished);
  EXPECT_FALSE(last.request_reset);
  EXPECT_FALSE(last.answer);
  EXPECT_EQ(ControllerProtocol::Phase::Finished, controller.phase());
  const std::uint64_t steps = learntSteps();

  // Whatever comes after: a new state, a repeat, a stray, a restarted sim.
  const std::vector<std::pair<Stamp, CartPoleState>> after{{tick(6), kUpright}, {tick(6), kUpright},
                                                           {tick(7), kSmall},   {0, kUpright},
                                                           {tick(1), kUpright}, {tick(1), kUpright}};
  for (const auto& message : after)
  {
    const Reaction r = controller.onState(message.first, message.second);
    EXPECT_EQ(Reaction::Kind::Finished, r.kind);
    EXPECT_FALSE(r.answer);
    EXPECT_FALSE(r.learned);
    EXPECT_FALSE(r.episode_began);
    EXPECT_FALSE(r.request_reset);
    EXPECT_FALSE(r.sim_restarted);
  }
  EXPECT_EQ(steps, learntSteps());
  EXPECT_EQ(2u, session_.episodesEnded());
}

TEST_F(ControllerProtocolTest, EvaluationNeverLearnsAndIsNotBoundByTheTrainingLimits)
{
  TrainingSession evaluator(config_.task, config_.agent, 0, false);
  params_.limits.max_episodes = 1;
  ControllerProtocol controller(evaluator, params_);
  const std::vector<double> values = evaluator.table().values();
  Stamp stamp = 0;
  for (int episode = 1; episode <= 3; ++episode)
  {
    EXPECT_TRUE(controller.onState(stamp += kTick, kUpright).episode_began);
    for (int i = 0; i < 4; ++i)
    {
      const Reaction r = controller.onState(stamp += kTick, kSmall);
      EXPECT_TRUE(r.answer);
      EXPECT_FALSE(r.learned);
      EXPECT_FALSE(controller.onState(stamp, kSmall).learned);  // a repeat
    }
    const Reaction fall = controller.onState(stamp += kTick, kFallen);
    EXPECT_TRUE(fall.episode_ended);
    EXPECT_FALSE(fall.learned);
    EXPECT_FALSE(fall.training_finished);
    EXPECT_TRUE(fall.request_reset);
  }
  EXPECT_EQ(3u, evaluator.episodesEnded());
  EXPECT_EQ(0u, evaluator.table().steps);
  EXPECT_EQ(0u, evaluator.table().episodes);
  EXPECT_TRUE(bitIdentical(values, evaluator.table().values()));
}

// --- The whole loop --------------------------------------------------------------------------

TEST(LockstepLoopback, TrainsExactlyAsHeadlessTrainer)
{
  const TrainingConfig config = shortConfig(30);
  LockstepLoopback loopback(config, 0);
  HeadlessTrainer headless(config, 0);
  const TrainingResult looped = loopback.run();
  const TrainingResult direct = headless.run();
  EXPECT_EQ(30u, looped.episodes);
  EXPECT_EQ(direct.episodes, looped.episodes);
  EXPECT_EQ(direct.steps, looped.steps);
  EXPECT_EQ(direct.steps, loopback.session().table().steps);
  EXPECT_TRUE(bitIdentical(headless.session().table().values(), loopback.session().table().values()));
  // Nothing is lost in one process: every command steps, no state is repeated.
  const SimProtocol::Counts& sim = loopback.simProtocol().counts();
  EXPECT_EQ(looped.steps, sim.steps);
  EXPECT_EQ(looped.episodes - 1, sim.resets);
  EXPECT_EQ(0u, sim.stale + sim.duplicate + sim.future + sim.unstamped + sim.repeats);
  const ControllerProtocol::Counts& controller = loopback.controllerProtocol().counts();
  EXPECT_EQ(looped.steps + looped.episodes, controller.states);
  EXPECT_EQ(0u, controller.repeats + controller.stale + controller.stray + controller.restarts);
}

TEST(LockstepLoopback, SolvesWithTheShippedConfigExactlyAsHeadlessTrainer)
{
  const TrainingConfig config = shippedConfig();
  LockstepLoopback loopback(config, 0);
  HeadlessTrainer headless(config, 0);
  const TrainingResult looped = loopback.run();
  const TrainingResult direct = headless.run();
  EXPECT_TRUE(looped.solved);
  EXPECT_TRUE(direct.solved);
  EXPECT_EQ(direct.episodes, looped.episodes);
  EXPECT_EQ(direct.steps, looped.steps);
  EXPECT_EQ(headless.session().table().episodes, loopback.session().table().episodes);
  EXPECT_TRUE(bitIdentical(headless.session().table().values(), loopback.session().table().values()));
}

// Several robots, one learner: the loopback's rounds (the learner node's order) and the
// headless trainer's give the same table for each robot count, and every robot takes part.
TEST(LockstepLoopback, SeveralRobotsTrainExactlyAsHeadlessTrainerWithTheSameRobots)
{
  for (const std::size_t robots : {2u, 3u, 4u})
  {
    SCOPED_TRACE(std::to_string(robots) + " robots");
    const TrainingConfig config = shippedConfig();
    LockstepLoopback loopback(config, 0, robots);
    HeadlessTrainer headless(config, 0, robots);
    std::vector<std::uint64_t> episodes_of(robots, 0);
    const TrainingResult looped = loopback.run([&](const EpisodeSummary& s) {
      ASSERT_LT(s.robot, robots);
      EXPECT_EQ(++episodes_of[s.robot], s.robot_episode);
    });
    const TrainingResult direct = headless.run();
    EXPECT_TRUE(looped.solved);
    EXPECT_EQ(direct.episodes, looped.episodes);
    EXPECT_EQ(direct.steps, looped.steps);
    EXPECT_TRUE(bitIdentical(headless.session().table().values(), loopback.session().table().values()));
    for (std::size_t r = 0; r < robots; ++r)
      EXPECT_GT(episodes_of[r], looped.episodes / robots / 2) << "robot " << r << " hardly took part";
  }
  // One robot is today's single sim: the same table as before robots existed.
  LockstepLoopback one(shippedConfig(), 0, 1);
  HeadlessTrainer single(shippedConfig(), 0);
  one.run();
  single.run();
  EXPECT_TRUE(bitIdentical(single.session().table().values(), one.session().table().values()));
}

namespace
{
// How often each fault strikes (every n-th message; 0: never).
struct Faults
{
  unsigned drop_state = 0;    // a state message is lost (the sim's repeat recovers it)
  unsigned replay_state = 0;  // an older state message is delivered again, once
  unsigned stray_state = 0;   // a state message without a stamp
  unsigned drop_answer = 0;   // an answer is lost (the sim repeats, the controller answers again)
  unsigned duplicate_answer = 0;
  unsigned late_answer = 0;    // a copy of an answer arrives after the next answer
  unsigned stray_command = 0;  // a third party's command: off-grid, older, or without a stamp
  unsigned slow_answer = 0;    // an answer arrives after the sim's timeout: the state went out again first
};

// What the commands carry: a stamp (JointState), or none (Float64, which a lockstep sim steps on
// whatever it answers), with the controller told so (~command_type float64) or not.
enum class Commands
{
  Stamped,
  Unstamped,
  UnstampedControllerNotTold
};

// The sim node and the controller node as they drive the protocol classes, wired by hand
// through message queues that lose, repeat and inject messages on a fixed script. The wall
// clock is fake: it jumps by repeat_after whenever nothing is in flight.
class ScriptedLink
{
public:
  ScriptedLink(const TrainingConfig& config, std::uint64_t seed, const Faults& faults,
               Commands commands = Commands::Stamped)
    : config_(config),
      seed_(seed),
      faults_(faults),
      commands_(commands),
      simulation_(config.physics, config.start_state_bound, seed),
      sim_(tickOf(config.physics.tau), kRepeatAfter),
      session_(config.task, config.agent, seed),
      controller_(session_, paramsOf(config, commands))
  {
  }

  void start()
  {
    simulation_.resetRandom();
    publish(sim_.start(now_));
  }

  // Delivers messages until `episodes` more episodes have ended or training is finished.
  void run(std::uint64_t episodes)
  {
    const std::uint64_t until = session_.episodesEnded() + episodes;
    for (std::uint64_t i = 0; !finished_ && session_.episodesEnded() < until; ++i)
    {
      if (i > 10000000)
        throw std::logic_error("the scripted link does not make progress");
      if (!deliverOne())
        repeat();
    }
  }

  // The sim process dies and a new one starts with the same parameters and seed.
  void restartSim()
  {
    to_controller_.clear();
    to_sim_.clear();
    simulation_ = CartPoleSimulation(config_.physics, config_.start_state_bound, seed_);
    sim_ = SimProtocol(tickOf(config_.physics.tau), kRepeatAfter);
    start();
  }

  // A stray publisher's flood taken for the sim's states (bad_messages.test's flood, which a
  // controller once took while the sim waited to repeat): for `messages` messages the sim's own
  // states are lost and the stray's delivered in their place, the kinds in turn: stamps older
  // than any (each once), an older stamp twice (a restarted sim's look), the sim's latest stamp
  // with other readings, a stamp just after it (not a tick) with a cart far outside the track,
  // and one just after it with plausible readings. The controller's answers reach the sim, which
  // steps on those that carry its pending stamp; and a hand on cart_effort (unstamped, which the
  // sim steps on whatever is pending) pushes at 10 N after every sixth. With `fall_by_hand`, the
  // hand goes on pushing after the last stray state until the pole has fallen. Then the stray
  // stops.
  void strayFlood(std::uint64_t messages, bool fall_by_hand)
  {
    hide_sim_ = true;
    const Stamp base = history_.empty() ? kTick : history_.back().stamp;
    for (std::uint64_t n = 0; n < messages; ++n)
    {
      const Stamp latest = history_.empty() ? kTick : history_.back().stamp;
      const Stamp just_after = latest + 1000 * (n % 15000 + 1);
      CartPoleState plausible;
      plausible << 0.01, 0.0, 0.02, -0.01;
      CartPoleState far = plausible;
      far[0] = n % 2 == 0 ? 1e300 : -1e300;
      switch (n % 5)
      {
        case 0:
          onState({base > 20 * kTick + 1000 * n ? base - 20 * kTick - 1000 * n : 1 + n, plausible});
          break;
        case 1: {
          const Stamp older = base > kTick + 1000 * (n % 15000) ? base - kTick - 1000 * (n % 15000) : 1;
          onState({older, plausible});
          onState({older, plausible});
          break;
        }
        case 2:
          onState({latest, plausible});
          break;
        case 3:
          onState({just_after, far});
          break;
        default:
          onState({just_after, plausible});
          break;
      }
      while (!to_sim_.empty())
        deliverOne();
      if (n % 6 == 5)
        pushByHand();
    }
    for (int i = 0; fall_by_hand && i < 1000 && !session_.task().isTerminal(simulation_.state()); ++i)
      pushByHand();
    to_controller_.clear();
    hide_sim_ = false;
  }

  void pushByHand()
  {
    sim_.onUnstampedCommand(now_);
    simulation_.step(10.0);
    publish(sim_.pending());
  }

  // One message delivered (states first); false when nothing is in flight.
  bool deliverOne()
  {
    now_ += std::chrono::milliseconds(1);
    if (!to_controller_.empty())
    {
      const StateMessage message = to_controller_.front();
      to_controller_.pop_front();
      onState(message);
      return true;
    }
    if (!to_sim_.empty())
    {
      const CommandMessage message = to_sim_.front();
      to_sim_.pop_front();
      onCommand(message);
      return true;
    }
    return false;
  }

  // The sim's timer finds the pending state unanswered for repeat_after.
  void repeat()
  {
    now_ += kRepeatAfter;
    if (!sim_.repeatDue(now_))
      throw std::logic_error("nothing in flight, yet no repeat due");
    publish(sim_.pending());
  }

  const TrainingSession& session() const
  {
    return session_;
  }
  const SimProtocol& sim() const
  {
    return sim_;
  }
  const ControllerProtocol& controller() const
  {
    return controller_;
  }
  bool finished() const
  {
    return finished_;
  }
  const std::vector<Reaction>& reactions() const
  {
    return reactions_;
  }
  std::uint64_t simSteps() const
  {
    return sim_steps_;
  }
  // Steps the sim took on a command that answered another state than the one it stepped from.
  std::uint64_t stepsOnAnotherStatesAnswer() const
  {
    return steps_on_another_states_answer_;
  }

private:
  struct StateMessage
  {
    Stamp stamp;
    CartPoleState state;
  };
  struct CommandMessage
  {
    Stamp stamp;
    double effort;
    Stamp answers = 0;  // the state it answers, which an unstamped command does not carry
  };

  static ControllerProtocolParams paramsOf(const TrainingConfig& config, Commands commands)
  {
    ControllerProtocolParams params;
    params.limits = config.limits;
    params.commands_unstamped = commands == Commands::Unstamped;
    return params;
  }

  static bool strikes(unsigned every, std::uint64_t count)
  {
    return every != 0 && count % every == 0;
  }

  void publish(Stamp stamp)
  {
    const StateMessage message{stamp, simulation_.state()};
    ++states_published_;
    if (!hide_sim_ && !strikes(faults_.drop_state, states_published_))
      to_controller_.push_back(message);
    if (strikes(faults_.stray_state, states_published_))
      to_controller_.push_back({0, CartPoleState::Constant(0.01)});
    // Each older stamp is replayed once only: twice would be a sim restart.
    if (strikes(faults_.replay_state, states_published_) && history_.size() >= 3)
    {
      const StateMessage old = history_[history_.size() - 3];
      if (replayed_.insert(old.stamp).second)
        to_controller_.push_back(old);
    }
    if (history_.empty() || history_.back().stamp != stamp)
      history_.push_back(message);
  }

  void onState(const StateMessage& message)
  {
    const Reaction reaction = controller_.onState(message.stamp, message.state);
    reactions_.push_back(reaction);
    if (reaction.training_finished)
      finished_ = true;
    if (reaction.request_reset)
    {
      // The reset service: served at once, while commands may still be in flight; its answer
      // reaches the controller right after the state it publishes.
      simulation_.resetRandom();
      publish(sim_.onReset(now_));
      controller_.onResetOutcome(true);
    }
    if (reaction.answer)
      send({reaction.stamp, reaction.effort});
  }

  void send(CommandMessage answer)
  {
    ++answers_sent_;
    answer.answers = answer.stamp;
    if (commands_ != Commands::Stamped)
      answer.stamp = 0;
    if (strikes(faults_.slow_answer, answers_sent_))
    {
      // A loaded machine: the sim's timer fires before the answer comes, and the state it sends
      // again reaches the controller first (states are delivered first).
      now_ += kRepeatAfter;
      if (sim_.repeatDue(now_))
        publish(sim_.pending());
    }
    if (strikes(faults_.stray_command, answers_sent_))
    {
      // A third party's commands, with efforts that would show in the trajectory.
      to_sim_.push_back({answer.stamp + 7, 3.0});
      to_sim_.push_back({answer.stamp > 2 * kTick ? answer.stamp - 2 * kTick : answer.stamp + 1, -7.0});
      to_sim_.push_back({0, 5.0});
    }
    if (!strikes(faults_.drop_answer, answers_sent_))
    {
      to_sim_.push_back(answer);
      if (strikes(faults_.duplicate_answer, answers_sent_))
        to_sim_.push_back(answer);
    }
    if (late_)
      to_sim_.push_back(*late_);
    late_.reset();
    if (strikes(faults_.late_answer, answers_sent_))
      late_ = answer;
  }

  void onCommand(const CommandMessage& message)
  {
    // cartpole_sim steps on every Float64 command (onEffort): it has no stamp to check.
    const SimProtocol::Verdict verdict =
        commands_ == Commands::Stamped ? sim_.onCommand(message.stamp, now_) : sim_.onUnstampedCommand(now_);
    if (verdict != SimProtocol::Verdict::Step)
      return;
    if (message.answers != 0 && message.answers + kTick != sim_.pending())
      ++steps_on_another_states_answer_;
    simulation_.step(message.effort);
    ++sim_steps_;
    publish(sim_.pending());
  }

  TrainingConfig config_;
  std::uint64_t seed_;
  Faults faults_;
  Commands commands_;
  CartPoleSimulation simulation_;
  SimProtocol sim_;
  TrainingSession session_;
  ControllerProtocol controller_;

  WallClock::time_point now_{};
  std::deque<StateMessage> to_controller_;
  std::deque<CommandMessage> to_sim_;
  std::optional<CommandMessage> late_;
  std::vector<StateMessage> history_;
  std::set<Stamp> replayed_;
  std::uint64_t states_published_ = 0;
  std::uint64_t answers_sent_ = 0;
  std::uint64_t sim_steps_ = 0;
  std::uint64_t steps_on_another_states_answer_ = 0;
  std::vector<Reaction> reactions_;
  bool finished_ = false;
  bool hide_sim_ = false;  // strayFlood: the sim's states are lost
};

Faults everyFault()
{
  Faults faults;
  faults.drop_state = 7;
  faults.replay_state = 19;
  faults.stray_state = 23;
  faults.drop_answer = 11;
  faults.duplicate_answer = 5;
  faults.late_answer = 13;
  faults.stray_command = 3;
  return faults;
}
}  // namespace

TEST(LockstepProtocol, ScriptedLinkWithoutFaultsTrainsAsTheLoopback)
{
  // The hand wiring itself is faithful: without faults it is the loopback.
  const TrainingConfig config = shortConfig(30);
  ScriptedLink link(config, 4, Faults());
  link.start();
  link.run(1000);
  LockstepLoopback loopback(config, 4);
  loopback.run();
  EXPECT_TRUE(link.finished());
  EXPECT_TRUE(bitIdentical(loopback.session().table().values(), link.session().table().values()));
  EXPECT_EQ(0u, link.sim().counts().repeats);
}

TEST(LockstepProtocol, AStrayFloodTakenForTheSimLeavesTrainingGoingOnceItStops)
{
  // Whatever the stray's states did to the episode under way (restarts, falls, resets), the
  // sim's own states, repeated while unanswered, bring training back; and when the last stray
  // state was a fall whose reset was served and the hand then felled the pole unseen (the sim
  // waits on a fall that is not the reset's start), a second reset does.
  for (const bool fall_by_hand : {false, true})
    for (const std::uint64_t at : {3u, 10u, 25u})
      for (const std::uint64_t length : {1u, 4u, 5u, 37u, 499u, 3001u, 3004u})
      {
        SCOPED_TRACE("after " + std::to_string(at) + " episodes, " + std::to_string(length) + " stray states" +
                     (fall_by_hand ? ", then a fall by hand" : ""));
        ScriptedLink link(shortConfig(60), 1, Faults());
        link.start();
        link.run(at);
        link.strayFlood(length, fall_by_hand);
        const std::uint64_t before = link.session().episodesEnded();
        EXPECT_NO_THROW(link.run(5));
        EXPECT_TRUE(link.finished() || link.session().episodesEnded() >= before + 5);
      }
}

TEST(LockstepProtocol, LostDuplicatedReplayedAndStrayMessagesLeaveTheTableBitForBitAsWithout)
{
  const TrainingConfig config = shortConfig(30);
  for (std::uint64_t seed = 0; seed < 3; ++seed)
  {
    ScriptedLink link(config, seed, everyFault());
    link.start();
    link.run(1000);
    HeadlessTrainer headless(config, seed);
    const TrainingResult result = headless.run();
    LockstepLoopback loopback(config, seed);
    loopback.run();

    ASSERT_TRUE(link.finished()) << "seed " << seed;
    EXPECT_EQ(30u, link.session().episodesEnded()) << "seed " << seed;
    EXPECT_EQ(result.steps, link.session().table().steps) << "seed " << seed;
    EXPECT_EQ(result.steps, link.simSteps()) << "seed " << seed;
    EXPECT_TRUE(bitIdentical(headless.session().table().values(), link.session().table().values())) << "seed " << seed;
    EXPECT_TRUE(bitIdentical(loopback.session().table().values(), link.session().table().values())) << "seed " << seed;

    // Every fault struck, and each was absorbed where the protocol says.
    const SimProtocol::Counts& sim = link.sim().counts();
    EXPECT_EQ(result.steps, sim.steps) << "seed " << seed;
    EXPECT_EQ(29u, sim.resets) << "seed " << seed;
    EXPECT_GT(sim.repeats, 0u) << "seed " << seed;
    EXPECT_GT(sim.duplicate, 0u) << "seed " << seed;
    EXPECT_GT(sim.stale, 0u) << "seed " << seed;
    EXPECT_GT(sim.future, 0u) << "seed " << seed;
    EXPECT_GT(sim.unstamped, 0u) << "seed " << seed;
    const ControllerProtocol::Counts& controller = link.controller().counts();
    EXPECT_EQ(result.steps + result.episodes, controller.states) << "seed " << seed;
    EXPECT_GT(controller.repeats, 0u) << "seed " << seed;
    EXPECT_GT(controller.stale, 0u) << "seed " << seed;
    EXPECT_GT(controller.stray, 0u) << "seed " << seed;
    EXPECT_EQ(0u, controller.restarts) << "seed " << seed;
  }
}

TEST(LockstepProtocol, UnstampedCommandsLateOrLostLeaveTheTableBitForBitAsWithout)
{
  // Float64 commands (robot profiles behind ros_control's JointEffortController, the sim posing as
  // them): answers that come after the sim's timeout, answers lost, states lost.
  const TrainingConfig config = shortConfig(30);
  Faults faults;
  faults.slow_answer = 5;
  faults.drop_answer = 11;
  faults.drop_state = 7;
  for (std::uint64_t seed = 0; seed < 3; ++seed)
  {
    ScriptedLink link(config, seed, faults, Commands::Unstamped);
    link.start();
    link.run(1000);
    HeadlessTrainer headless(config, seed);
    const TrainingResult result = headless.run();
    ASSERT_TRUE(link.finished()) << "seed " << seed;
    EXPECT_EQ(result.steps, link.simSteps()) << "seed " << seed;
    EXPECT_EQ(0u, link.stepsOnAnotherStatesAnswer()) << "seed " << seed;
    EXPECT_TRUE(bitIdentical(headless.session().table().values(), link.session().table().values())) << "seed " << seed;
    EXPECT_GT(link.sim().counts().repeats, 0u) << "seed " << seed;
    EXPECT_GT(link.controller().counts().repeats, 0u) << "seed " << seed;
  }
}

TEST(LockstepProtocol, AControllerNotToldItsCommandsAreUnstampedStepsTheSimTwiceOnALateAnswer)
{
  // What commands_unstamped prevents: the repeat of a late answer's state answered too, both
  // answers stepping the sim, and from then on every command a step late: the sim steps more
  // often than the controller decides, and the table is not the one headless training makes.
  const TrainingConfig config = shortConfig(30);
  Faults faults;
  faults.slow_answer = 50;
  ScriptedLink link(config, 0, faults, Commands::UnstampedControllerNotTold);
  link.start();
  link.run(1000);
  HeadlessTrainer headless(config, 0);
  headless.run();
  EXPECT_GT(link.stepsOnAnotherStatesAnswer(), link.simSteps() / 2)
      << link.stepsOnAnotherStatesAnswer() << " of " << link.simSteps();
  EXPECT_FALSE(bitIdentical(headless.session().table().values(), link.session().table().values()));
}

TEST_F(ControllerProtocolTest, WithUnstampedCommandsARepeatOfAnAnsweredStateIsAnsweredOnlyEveryThirdTime)
{
  params_.commands_unstamped = true;
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(1), kUpright);
  const Reaction first = controller.onState(tick(2), kSmall);
  ASSERT_TRUE(first.answer);
  std::vector<bool> answered;
  for (int repeat = 0; repeat < 7; ++repeat)
  {
    const Reaction r = controller.onState(tick(2), kSmall);
    EXPECT_EQ(Reaction::Kind::Repeat, r.kind);
    answered.push_back(r.answer);
    if (r.answer)
    {
      EXPECT_EQ(first.effort, r.effort);
    }
  }
  // The answer may have been lost (the sim's subscription not connected yet): the third repeat
  // is answered, and so on; a late answer is long in by then.
  EXPECT_EQ((std::vector<bool>{false, false, true, false, false, true, false}), answered);
  // A new state is answered at once, and its first repeat held back again.
  EXPECT_TRUE(controller.onState(tick(3), kSmall).answer);
  EXPECT_FALSE(controller.onState(tick(3), kSmall).answer);
  EXPECT_EQ(7u + 1u, controller.counts().repeats);
}

TEST(LockstepProtocol, ASimRestartedMidEpisodeIsTakenUpOnItsFirstRepeatAndTrainingGoesOn)
{
  const TrainingConfig config = shortConfig(20);
  ScriptedLink link(config, 2, Faults());
  link.start();
  link.run(5);
  // Into an episode, a few steps on.
  for (int i = 0; i < 6 || !link.session().inEpisode(); ++i)
    ASSERT_TRUE(link.deliverOne());
  const std::uint64_t ended = link.session().episodesEnded();
  const std::uint64_t learnt = link.session().table().steps;

  link.restartSim();
  ASSERT_TRUE(link.deliverOne());
  EXPECT_EQ(Reaction::Kind::Stale, link.reactions().back().kind);
  EXPECT_FALSE(link.deliverOne());  // not answered: the sim waits
  link.repeat();
  ASSERT_TRUE(link.deliverOne());
  const Reaction restart = link.reactions().back();
  EXPECT_TRUE(restart.sim_restarted);
  EXPECT_TRUE(restart.episode_began);
  EXPECT_TRUE(restart.answer);
  EXPECT_EQ(tick(1), restart.stamp);
  EXPECT_EQ(ended, link.session().episodesEnded());
  EXPECT_EQ(learnt, link.session().table().steps);

  link.run(1000);
  EXPECT_TRUE(link.finished());
  EXPECT_EQ(20u, link.session().episodesEnded());
  EXPECT_EQ(1u, link.controller().counts().restarts);
  EXPECT_EQ(0u, link.sim().counts().stale + link.sim().counts().future);
}

TEST(ReactionSaid, AResetThatSetsTimeBackIsSaidOnceAsWhatItIsNotAsDropsAndRestarts)
{
  const auto ready = [] { return true; };
  Reaction stale;
  stale.kind = Reaction::Kind::Stale;
  stale.awaiting_reset = true;
  ControllerProtocol::Counts counts;
  counts.stale = 1;
  EXPECT_TRUE(reactionLog(stale, counts, "/cartpole_v0/joint_states", 0.02, ready, ready).empty());
  Reaction restart;
  restart.sim_restarted = true;
  restart.awaiting_reset = true;
  counts.restarts = counts.resets_back = 1;
  const LogLines first = reactionLog(restart, counts, "/cartpole_v0/joint_states", 0.04, ready, ready);
  ASSERT_EQ(1u, first.size());
  EXPECT_EQ(LogLine::Level::Info, first[0].level);
  EXPECT_EQ(
      "/cartpole_v0/joint_states: the reset set time back to 0.040 s (as Gazebo's reset_simulation does): "
      "each reset's start is taken from where time goes on (said once)",
      first[0].text);
  counts.restarts = counts.resets_back = 2;
  EXPECT_TRUE(reactionLog(restart, counts, "/cartpole_v0/joint_states", 0.04, ready, ready).empty());
  // Not awaited: a restart, warned as before.
  restart.awaiting_reset = false;
  EXPECT_EQ(LogLine::Level::Warn, reactionLog(restart, counts, "x", 0.04, ready, ready).at(0).level);
}

TEST_F(ControllerProtocolTest, TimeSetBackByTheResetAskedForIsMarkedAsAwaited)
{
  // Gazebo's reset_simulation: the fall, the reset asked for, then states from time 0 again.
  ControllerProtocol controller(session_, params_);
  controller.onState(tick(100), kUpright);
  ASSERT_TRUE(controller.onState(tick(101), kFallen).request_reset);
  controller.onResetOutcome(true);
  const Reaction first = controller.onState(tick(1), kUpright);
  EXPECT_EQ(Reaction::Kind::Stale, first.kind);
  EXPECT_TRUE(first.awaiting_reset);
  controller.onState(tick(2), kUpright);
  const Reaction r = controller.onState(tick(3), kUpright);
  EXPECT_TRUE(r.sim_restarted);
  EXPECT_TRUE(r.awaiting_reset);
  EXPECT_TRUE(r.episode_began);
  EXPECT_EQ(1u, controller.counts().resets_back);
  // Mid-episode, time back is no reset of ours.
  controller.onState(tick(4), kSmall);
  controller.onState(tick(1), kSmall);
  controller.onState(tick(2), kSmall);
  const Reaction restart = controller.onState(tick(3), kSmall);
  EXPECT_TRUE(restart.sim_restarted);
  EXPECT_FALSE(restart.awaiting_reset);
  EXPECT_EQ(1u, controller.counts().resets_back);
}

TEST(ReactionSaid, SaysWhatHappenedAndAsksTheThrottleOnlyForWhatItThrottles)
{
  int asked = 0;
  const auto ready = [&] {
    ++asked;
    return true;
  };
  Reaction answered;
  answered.answer = true;
  EXPECT_TRUE(reactionLog(answered, {}, "/cartpole/joint_states", 1.0, ready, ready).empty());
  EXPECT_EQ(0, asked);
  Reaction restarted;
  restarted.sim_restarted = true;
  ControllerProtocol::Counts counts;
  counts.restarts = 2;
  const LogLines log = reactionLog(restarted, counts, "/cartpole/joint_states", 0.06, ready, [] { return false; });
  EXPECT_TRUE(log.empty());  // throttled
  const LogLines allowed = reactionLog(restarted, counts, "/cartpole/joint_states", 0.06, ready, ready);
  ASSERT_EQ(1u, allowed.size());
  EXPECT_EQ(LogLine::Level::Warn, allowed[0].level);
  EXPECT_NE(std::string::npos, allowed[0].text.find("time went back to 0.060 s")) << allowed[0].text;
  EXPECT_NE(std::string::npos, allowed[0].text.find("Restarts so far: 2")) << allowed[0].text;
  Reaction stale;
  stale.kind = Reaction::Kind::Stale;
  EXPECT_EQ(1u, reactionLog(stale, counts, "/cartpole/joint_states", 0.5, ready, ready).size());
  EXPECT_EQ(2, asked);  // the restart's throttle once, the dropped state's once
}
