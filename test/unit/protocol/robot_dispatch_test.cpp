// RobotDispatch: which robot's state the learner serves, and when, driven through scripted orders
// of states and timer ticks on a fake wall clock; and robots whose states arrive in any order,
// which must train exactly as the loopback serves them in rounds.
#include "test_support.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "lockstep_loopback.h"
#include "cartpole_qlearning/protocol/robot_dispatch.h"
#include "cartpole_qlearning/node_settings/node_setting_names.h"

#include <gtest/gtest.h>

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

using cartpole_qlearning::test::bitIdentical;
using namespace cartpole_qlearning;
using std::chrono::milliseconds;

namespace
{
const Stamp kTick = 20000000;  // tau = 0.02 s, the shipped config's
const Stamp kMs = 1000000;
const WallClock::time_point kT0{};  // a fake wall clock: only differences matter

Stamp tick(std::uint64_t n)
{
  return n * kTick;
}

TrainingConfig shippedConfig()
{
  return readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/cartpole.yaml"));
}

// As a driver that sends velocities reads the state (the default mapping: no offsets, no signs).
JointReadings readings(const CartPoleState& s)
{
  JointReadings r;
  r.cart_position = s[0];
  r.cart_velocity = s[1];
  r.pole_position = s[2];
  r.pole_velocity = s[3];
  return r;
}

const CartPoleState kUpright = CartPoleState::Zero();
const CartPoleState kFallen(0.0, 0.0, 0.5, 0.0);

std::vector<std::string> robotNames(std::size_t robots)
{
  std::vector<std::string> names;
  for (std::size_t r = 0; r < robots; ++r)
    names.push_back("/robot_" + std::to_string(r) + "/joint_states");
  return names;
}

// What the lines say, one string, to search in.
std::string text(const LogLines& log)
{
  std::string all;
  for (const LogLine& line : log)
    all += line.text + "\n";
  return all;
}

class RobotDispatchTest : public ::testing::Test
{
protected:
  RobotDispatch& make(std::size_t robots, bool sync = true)
  {
    session_ = std::make_unique<TrainingSession>(config_.task, config_.agent, 0, true, robots);
    params_.robots = robotNames(robots);
    params_.names = nodeSettingNames();
    params_.sync = sync;
    params_.silent_after_s = 1.0;
    params_.robot.decision_period = 0.02;
    params_.protocol.limits = config_.limits;
    dispatch_ = std::make_unique<RobotDispatch>(*session_, params_, kT0);
    return *dispatch_;
  }

  // The robots served, in order, until next() has nothing more.
  std::vector<std::size_t> servedRobots(WallClock::time_point now = kT0)
  {
    std::vector<std::size_t> served;
    while (const std::optional<RobotDispatch::Turn> turn = dispatch_->next(now))
      served.push_back(turn->robot);
    return served;
  }

  TrainingConfig config_ = shippedConfig();
  RobotDispatchParams params_;
  std::unique_ptr<TrainingSession> session_;
  std::unique_ptr<RobotDispatch> dispatch_;
};

TEST_F(RobotDispatchTest, OneRobotsStatesAreServedAsTheyComeAndAnsweredWithTheirStamps)
{
  RobotDispatch& dispatch = make(1);
  EXPECT_FALSE(dispatch.next(kT0)) << "nothing arrived yet";
  const RobotDispatch::Orders orders = dispatch.onState(0, tick(1), readings(kUpright), kT0);
  EXPECT_FALSE(orders.hold);
  EXPECT_TRUE(orders.log.empty());
  std::optional<RobotDispatch::Turn> turn = dispatch.next(kT0);
  ASSERT_TRUE(turn);
  EXPECT_EQ(0u, turn->robot);
  EXPECT_EQ(tick(1), turn->stamp);
  EXPECT_EQ(Reaction::Kind::New, turn->reaction.kind);
  EXPECT_TRUE(turn->reaction.answer);
  EXPECT_EQ(tick(1), turn->reaction.stamp);
  EXPECT_FALSE(dispatch.next(kT0)) << "a state is served once";

  dispatch.onState(0, tick(1), readings(kUpright), kT0);
  turn = dispatch.next(kT0);
  ASSERT_TRUE(turn);
  EXPECT_EQ(Reaction::Kind::Repeat, turn->reaction.kind);
  EXPECT_TRUE(turn->reaction.answer) << "its first answer may have been lost";
}

TEST_F(RobotDispatchTest, NewStatesWaitForTheRoundWhichIsServedInRobotOrderWhileRepeatsPassAtOnce)
{
  RobotDispatch& dispatch = make(3);
  dispatch.onState(2, tick(1), readings(kUpright), kT0);
  dispatch.onState(0, tick(1), readings(kUpright), kT0);
  EXPECT_TRUE(servedRobots().empty()) << "robot 1 has no state yet";
  dispatch.onState(1, tick(1), readings(kUpright), kT0);
  EXPECT_EQ((std::vector<std::size_t>{0, 1, 2}), servedRobots());

  // The next round: robot 2's new state waits; robot 0's repeat is answered at once, without
  // touching the session.
  dispatch.onState(2, tick(2), readings(kUpright), kT0);
  dispatch.onState(0, tick(1), readings(kUpright), kT0);
  std::optional<RobotDispatch::Turn> turn = dispatch.next(kT0);
  ASSERT_TRUE(turn);
  EXPECT_EQ(0u, turn->robot);
  EXPECT_EQ(Reaction::Kind::Repeat, turn->reaction.kind);
  EXPECT_FALSE(dispatch.next(kT0));
  dispatch.onState(0, tick(2), readings(kUpright), kT0);
  dispatch.onState(1, tick(2), readings(kUpright), kT0);
  EXPECT_EQ((std::vector<std::size_t>{0, 1, 2}), servedRobots());
}

TEST_F(RobotDispatchTest, WithoutSyncEveryStateIsServedAsItComes)
{
  RobotDispatch& dispatch = make(3, false);
  for (const std::size_t r : {2u, 0u, 2u})
  {
    dispatch.onState(r, r == 2 ? tick(1) : tick(5), readings(kUpright), kT0);
    EXPECT_EQ(std::vector<std::size_t>{r}, servedRobots());
  }
}

TEST_F(RobotDispatchTest, StatesWithinTheDecisionPeriodAreHeldExceptAFall)
{
  RobotDispatch& dispatch = make(1);
  // A 100 Hz driver, decisions every 20 ms.
  EXPECT_FALSE(dispatch.onState(0, 1000 * kMs, readings(kUpright), kT0).hold);
  EXPECT_EQ(1u, servedRobots().size());
  EXPECT_TRUE(dispatch.onState(0, 1010 * kMs, readings(kUpright), kT0).hold);
  EXPECT_TRUE(servedRobots().empty()) << "a held state is answered with the effort held, not served";
  EXPECT_FALSE(dispatch.onState(0, 1020 * kMs, readings(kUpright), kT0).hold);
  EXPECT_EQ(1u, servedRobots().size());
  // The pole falls 10 ms after a decision: the episode ends now, not a period later.
  EXPECT_FALSE(dispatch.onState(0, 1030 * kMs, readings(kFallen), kT0).hold);
  const std::optional<RobotDispatch::Turn> turn = dispatch.next(kT0);
  ASSERT_TRUE(turn);
  EXPECT_TRUE(turn->reaction.episode_ended);
  EXPECT_TRUE(turn->reaction.request_reset);
  // Between episodes a fallen pole is no fall: held as any state within the period (the fall was
  // served out of the clock's turn, so the period runs from 1020 ms still).
  EXPECT_TRUE(dispatch.onState(0, 1035 * kMs, readings(kFallen), kT0).hold);
}

TEST_F(RobotDispatchTest, SlowStatesAreSaidAtMostOnceInTenSecondsOfWallTime)
{
  RobotDispatch& dispatch = make(1);
  const std::string slow =
      "joint_states on /robot_0/joint_states come further apart than ~decision_period = "
      "0.02 s, the step the table learns";
  dispatch.onState(0, 1000 * kMs, readings(kUpright), kT0);
  const RobotDispatch::Orders first = dispatch.onState(0, 1066 * kMs, readings(kUpright), kT0);  // 15 Hz
  ASSERT_EQ(1u, first.log.size());
  EXPECT_EQ(LogLine::Level::Warn, first.log[0].level);
  EXPECT_EQ(slow, first.log[0].text);
  EXPECT_TRUE(dispatch.onState(0, 1132 * kMs, readings(kUpright), kT0 + milliseconds(9999)).log.empty());
  EXPECT_EQ(slow + "\n", text(dispatch.onState(0, 1198 * kMs, readings(kUpright), kT0 + milliseconds(10000)).log));
}

TEST_F(RobotDispatchTest, ASilentRobotIsStoppedAndSaidOnceAndDropsOutOfTheRoundsUntilItIsBack)
{
  RobotDispatch& dispatch = make(2);
  EXPECT_TRUE(dispatch.onTick(kT0 + milliseconds(999)).stop.empty());
  dispatch.onState(0, tick(1), readings(kUpright), kT0 + milliseconds(500));
  RobotDispatch::Orders orders = dispatch.onTick(kT0 + milliseconds(1000));
  EXPECT_EQ(std::vector<std::size_t>{1}, orders.stop) << "robot 1 silent since the start; robot 0 heard 0.5 s ago";
  EXPECT_EQ(
      "no joint_states on /robot_1/joint_states for 1.0 s: is its cartpole_sim running? Waiting for it\n"
      "/robot_1/joint_states is silent; the rounds go on without it until it is back\n",
      text(orders.log));
  // The round of robot 0 alone goes on.
  EXPECT_EQ(std::vector<std::size_t>{0}, servedRobots());
  orders = dispatch.onTick(kT0 + milliseconds(1200));
  EXPECT_TRUE(orders.stop.empty()) << "said once";
  EXPECT_TRUE(orders.log.empty());
  EXPECT_EQ(std::vector<std::size_t>{0}, dispatch.onTick(kT0 + milliseconds(1500)).stop);

  orders = dispatch.onState(1, tick(1), readings(kUpright), kT0 + milliseconds(1600));
  EXPECT_EQ(
      "joint_states are back on /robot_1/joint_states; going on\n"
      "/robot_1/joint_states takes part in the rounds again\n",
      text(orders.log));
  EXPECT_TRUE(servedRobots().empty()) << "robot 0, silent while nobody waited, still takes part";
  EXPECT_EQ("joint_states are back on /robot_0/joint_states; going on\n",
            text(dispatch.onState(0, tick(2), readings(kUpright), kT0 + milliseconds(1700)).log));
  EXPECT_EQ((std::vector<std::size_t>{0, 1}), servedRobots());
}

TEST_F(RobotDispatchTest, ARobotsSilenceNamesItsStateTopicAndItsDriverNotASim)
{
  params_.simulated = false;  // robot.launch: no cartpole_sim's reset service
  RobotDispatch& dispatch = make(1);
  const RobotDispatch::Orders orders = dispatch.onTick(kT0 + milliseconds(1000));
  EXPECT_EQ(std::vector<std::size_t>{0}, orders.stop);
  EXPECT_EQ(
      "no joint_states on /robot_0/joint_states for 1.0 s: no driver publishes them. Is the robot's driver running, "
      "and ~state_topic (robot.launch joint_states:=) the topic it publishes? Waiting for it\n",
      text(orders.log));
  EXPECT_EQ(std::string::npos, text(orders.log).find("cartpole_sim"));
}

TEST_F(RobotDispatchTest, ADriverThatPublishesOnlyUnusableStatesIsNotSaidToPublishNothing)
{
  params_.simulated = false;
  RobotDispatch& dispatch = make(1);
  // NaN states at 50 Hz (the node drops them as invalid): the driver is there, its states are not.
  for (int ms = 0; ms < 1000; ms += 20)
    dispatch.onInvalid(0, tick(1) + static_cast<Stamp>(ms) * kMs, kT0 + milliseconds(ms), "/driver");
  const RobotDispatch::Orders orders = dispatch.onTick(kT0 + milliseconds(1000));
  EXPECT_EQ(std::vector<std::size_t>{0}, orders.stop);
  EXPECT_EQ(
      "no usable joint_states on /robot_0/joint_states for 1.0 s: they keep coming, but none could be used (see the "
      "warnings about them above). Waiting for usable ones\n",
      text(orders.log));
  EXPECT_TRUE(dispatch.onTick(kT0 + milliseconds(1500)).log.empty()) << "said once";
}

TEST_F(RobotDispatchTest, AFailedResetKeepsASpinningPoleFromStartingEpisodesUntilItIsInTheStartRegion)
{
  RobotDispatch& dispatch = make(1);
  const auto serveOne = [&](Stamp stamp, const CartPoleState& state) {
    dispatch.onState(0, stamp, readings(state), kT0);
    const std::optional<RobotDispatch::Turn> turn = dispatch.next(kT0);
    EXPECT_TRUE(turn);
    return turn ? turn->reaction : Reaction();
  };
  ASSERT_TRUE(serveOne(tick(1), kUpright).episode_began);
  ASSERT_TRUE(serveOne(tick(2), kFallen).request_reset);
  dispatch.onResetOutcome(0, false);
  // The pole spins: it passes upright (not fallen) fast, outside the start region.
  for (std::uint64_t n = 3; n < 40; ++n)
  {
    const Reaction r = serveOne(tick(n), CartPoleState(0.0, 0.0, n % 2 ? 0.05 : 2.0, 8.0));
    EXPECT_FALSE(r.episode_began) << n;
    EXPECT_TRUE(r.answer);
    EXPECT_EQ(0.0, r.effort);
  }
  EXPECT_EQ(1u, session_->episodesEnded());
  EXPECT_TRUE(serveOne(tick(40), kUpright).episode_began) << "stood up by hand";
}

TEST_F(RobotDispatchTest, ADroppedStateIsSaidAtMostOnceASecondOfWallTime)
{
  RobotDispatch& dispatch = make(1);
  dispatch.onState(0, tick(5), readings(kUpright), kT0);
  servedRobots();
  dispatch.onState(0, tick(3), readings(kUpright), kT0);
  std::optional<RobotDispatch::Turn> turn = dispatch.next(kT0);
  ASSERT_TRUE(turn);
  EXPECT_EQ(Reaction::Kind::Stale, turn->reaction.kind);
  EXPECT_NE(std::string::npos,
            text(turn->log).find("dropped joint_states on /robot_0/joint_states stamped 0.060000, older than"))
      << text(turn->log);
  dispatch.onState(0, tick(2), readings(kUpright), kT0 + milliseconds(999));
  turn = dispatch.next(kT0 + milliseconds(999));
  ASSERT_TRUE(turn);
  EXPECT_TRUE(turn->log.empty()) << text(turn->log);
  dispatch.onState(0, tick(1), readings(kUpright), kT0 + milliseconds(1000));
  turn = dispatch.next(kT0 + milliseconds(1000));
  ASSERT_TRUE(turn);
  EXPECT_NE(std::string::npos, text(turn->log).find("Dropped so far: 3")) << text(turn->log);
}

// The sims of LockstepLoopback, their states delivered to the dispatch in a scrambled order (as
// several sim processes' messages arrive): the rounds put them back in robot order, so the table
// is the loopback's, bit for bit.
TEST(RobotDispatch, RobotsWhoseStatesArriveInAnyOrderTrainExactlyAsTheLoopback)
{
  const std::size_t robots = 3;
  TrainingConfig config = shippedConfig();
  config.limits.max_episodes = 150;
  config.limits.stop_when_solved = false;

  TrainingSession session(config.task, config.agent, 0, true, robots);
  RobotDispatchParams params;
  params.robots = robotNames(robots);
  params.robot.decision_period = config.physics.tau;
  params.protocol.limits = config.limits;
  RobotDispatch dispatch(session, params, kT0);

  struct Sim
  {
    CartPoleSimulation simulation;
    SimProtocol protocol;
  };
  std::vector<std::unique_ptr<Sim>> sims;
  std::deque<std::size_t> in_flight;  // robots whose pending state is on its way
  for (std::size_t r = 0; r < robots; ++r)
  {
    sims.push_back(std::make_unique<Sim>(
        Sim{CartPoleSimulation(config.physics, config.start_state_bound, robotSeed(0, r), config.perturbations),
            SimProtocol(tickOf(config.physics.tau), WallClock::duration::max())}));
    sims[r]->simulation.resetRandom();
    sims[r]->protocol.start(kT0);
    in_flight.push_front(r);
  }
  std::mt19937 arrival(7);
  std::uint64_t episodes = 0;
  bool finished = false;
  while (!finished)
  {
    ASSERT_FALSE(in_flight.empty());
    const std::size_t pick = arrival() % in_flight.size();
    const std::size_t r = in_flight[pick];
    in_flight.erase(in_flight.begin() + static_cast<std::ptrdiff_t>(pick));
    ASSERT_FALSE(
        dispatch.onState(r, sims[r]->protocol.pending(), readings(sims[r]->simulation.observation()), kT0).hold);
    while (const std::optional<RobotDispatch::Turn> turn = dispatch.next(kT0))
    {
      Sim& sim = *sims[turn->robot];
      episodes += turn->reaction.episode_ended ? 1 : 0;
      if (turn->reaction.training_finished)
      {
        finished = true;
        break;
      }
      if (turn->reaction.request_reset)
      {
        sim.simulation.resetRandom();
        sim.protocol.onReset(kT0);
      }
      else
      {
        ASSERT_TRUE(turn->reaction.answer);
        ASSERT_EQ(SimProtocol::Verdict::Step, sim.protocol.onCommand(turn->reaction.stamp, kT0));
        sim.simulation.step(turn->reaction.effort);
      }
      in_flight.push_back(turn->robot);
    }
  }

  LockstepLoopback loopback(config, 0, robots);
  const TrainingResult looped = loopback.run();
  EXPECT_EQ(looped.episodes, episodes);
  EXPECT_EQ(loopback.session().table().steps, session.table().steps);
  EXPECT_TRUE(bitIdentical(loopback.session().table().values(), session.table().values()));
}

}  // namespace

// The freshness guard on the dispatch's paths: the answer to a frozen stamp, a hold between
// decisions, invalid readings and a second publisher, each ending in 0 within the bound.
TEST_F(RobotDispatchTest, FrozenStampsAreAnsweredWithZeroOnceTheBoundHasPassed)
{
  params_.freshness_timeout_s = 0.1;
  RobotDispatch& dispatch = make(1);
  WallClock::time_point now = kT0;
  std::optional<RobotDispatch::Turn> turn;
  // Some fresh states: an episode runs, efforts of +-10 go out.
  Stamp s = 0;
  for (int i = 1; i <= 5; ++i)
  {
    now += milliseconds(20);
    s = tick(static_cast<std::uint64_t>(i));
    dispatch.onState(0, s, readings(kUpright), now, "/driver");
    turn = dispatch.next(now);
    ASSERT_TRUE(turn);
    ASSERT_NE(0.0, turn->reaction.effort);
  }
  const double effort = turn->reaction.effort;
  // The driver republishes its last message: the same effort within the bound, 0 past it.
  now += milliseconds(50);
  dispatch.onState(0, s, readings(kUpright), now, "/driver");
  turn = dispatch.next(now);
  ASSERT_TRUE(turn);
  EXPECT_EQ(Reaction::Kind::Repeat, turn->reaction.kind);
  EXPECT_EQ(effort, turn->reaction.effort);
  now += milliseconds(60);
  const RobotDispatch::Orders tick_orders = dispatch.onTick(now);
  EXPECT_EQ(std::vector<std::size_t>{0}, tick_orders.stop);
  EXPECT_NE(std::string::npos, text(tick_orders.log).find("frozen stamps")) << text(tick_orders.log);
  dispatch.onState(0, s, readings(kUpright), now, "/driver");
  turn = dispatch.next(now);
  ASSERT_TRUE(turn);
  EXPECT_TRUE(turn->reaction.answer);
  EXPECT_EQ(0.0, turn->reaction.effort) << "a stale decision's effort is not sent again";
  // A fresh state: efforts again.
  now += milliseconds(20);
  dispatch.onState(0, tick(6), readings(kUpright), now, "/driver");
  turn = dispatch.next(now);
  ASSERT_TRUE(turn);
  EXPECT_NE(0.0, turn->reaction.effort);
  EXPECT_NE(std::string::npos, text(turn->log).find("again")) << text(turn->log);
}

TEST_F(RobotDispatchTest, HoldsBetweenDecisionsTurnToZeroWhenNoDecisionComes)
{
  params_.freshness_timeout_s = 0.1;
  RobotDispatch& dispatch = make(1);
  params_.robot.decision_period = 0.02;
  WallClock::time_point now = kT0 + milliseconds(1);
  dispatch.onState(0, tick(1), readings(kUpright), now, "/driver");
  ASSERT_TRUE(dispatch.next(now));
  // NaN bursts: dropped, counted, and past the bound the guard stops the robot.
  for (int i = 0; i < 10; ++i)
  {
    now += milliseconds(20);
    const RobotDispatch::Orders orders = dispatch.onInvalid(0, tick(2) + static_cast<Stamp>(i) * kMs, now, "/driver");
    EXPECT_TRUE(orders.drop);
  }
  const RobotDispatch::Orders stop = dispatch.onTick(now);
  EXPECT_EQ(std::vector<std::size_t>{0}, stop.stop);
  EXPECT_NE(std::string::npos, text(stop.log).find("NaN")) << text(stop.log);
  // A state a millisecond after the last decided one is held (within the decision period): with 0.
  now += milliseconds(1);
  const RobotDispatch::Orders hold = dispatch.onState(0, tick(1) + kMs, readings(kUpright), now, "/driver");
  EXPECT_TRUE(hold.hold);
  EXPECT_TRUE(hold.hold_zero);
}

TEST_F(RobotDispatchTest, ASecondPublishersStatesAreDroppedWithAnErrorNamingBoth)
{
  params_.freshness_timeout_s = 0.1;
  RobotDispatch& dispatch = make(1);
  WallClock::time_point now = kT0 + milliseconds(1);
  dispatch.onState(0, tick(1), readings(kUpright), now, "/driver");
  ASSERT_TRUE(dispatch.next(now));
  now += milliseconds(10);
  const RobotDispatch::Orders second = dispatch.onState(0, tick(2), readings(kUpright), now, "/other_driver");
  EXPECT_TRUE(second.drop);
  EXPECT_FALSE(dispatch.next(now)) << "nothing to serve from the second driver";
  ASSERT_EQ(1u, second.log.size());
  EXPECT_EQ(LogLine::Level::Error, second.log[0].level);
  EXPECT_NE(std::string::npos, second.log[0].text.find("/driver and /other_driver")) << second.log[0].text;
}

TEST_F(RobotDispatchTest, WithTheGuardOffARepeatIsAnsweredWithItsEffortHoweverLate)
{
  RobotDispatch& dispatch = make(1);  // freshness_timeout_s 0: a lockstep sim
  dispatch.onState(0, tick(1), readings(kUpright), kT0, "/sim");
  const std::optional<RobotDispatch::Turn> first = dispatch.next(kT0);
  ASSERT_TRUE(first);
  dispatch.onState(0, tick(1), readings(kUpright), kT0 + milliseconds(5000), "/sim");
  const std::optional<RobotDispatch::Turn> repeat = dispatch.next(kT0 + milliseconds(5000));
  ASSERT_TRUE(repeat);
  EXPECT_EQ(first->reaction.effort, repeat->reaction.effort);
  EXPECT_TRUE(dispatch.onTick(kT0 + milliseconds(5000)).stop.size() <= 1) << "only the silence report";
}
