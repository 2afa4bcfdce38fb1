// RobotRounds: when a learner serving several robots takes their states.
#include "cartpole_qlearning/protocol/robot_rounds.h"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

namespace
{
using cartpole_qlearning::RobotRounds;
using cartpole_qlearning::WallClock;
using std::chrono::milliseconds;

const WallClock::duration kTimeout = milliseconds(1000);
const WallClock::time_point kT0{};

TEST(RobotRounds, OneRobotsStateMakesARoundAtOnce)
{
  RobotRounds rounds(1, true, kTimeout, kT0);
  EXPECT_FALSE(rounds.roundComplete()) << "a round of nothing";
  rounds.hold(0);
  EXPECT_TRUE(rounds.roundComplete());
  rounds.take(0);
  EXPECT_FALSE(rounds.roundComplete());
}

TEST(RobotRounds, ARoundWaitsForEveryRobotThatTakesPart)
{
  RobotRounds rounds(3, true, kTimeout, kT0);
  rounds.hold(2);
  rounds.hold(0);
  rounds.hold(0);  // a newer state of the same robot replaces the one waiting
  EXPECT_FALSE(rounds.roundComplete()) << "robot 1 has no state yet";
  rounds.hold(1);
  EXPECT_TRUE(rounds.roundComplete());
  for (std::size_t r = 0; r < 3; ++r)
  {
    EXPECT_TRUE(rounds.held(r));
    rounds.take(r);
  }
  EXPECT_FALSE(rounds.roundComplete());
}

TEST(RobotRounds, ASilentRobotDropsOutOnlyWhileOthersWaitAndRejoinsWhenHeard)
{
  const WallClock::time_point t0 = kT0 + milliseconds(100);
  RobotRounds rounds(3, true, kTimeout, kT0);
  EXPECT_EQ(milliseconds(100), rounds.silentFor(2, t0)) << "silent since the start";
  for (std::size_t r = 0; r < 3; ++r)
    rounds.heard(r, t0);
  // Nobody waits: silence holds nobody up, so nobody drops out.
  EXPECT_TRUE(rounds.dropOuts(t0 + milliseconds(5000)).empty());

  rounds.heard(1, t0 + milliseconds(4500));
  rounds.heard(0, t0 + milliseconds(5000));
  rounds.hold(0);
  rounds.heard(2, t0 + milliseconds(5000));
  rounds.hold(2);
  EXPECT_TRUE(rounds.dropOuts(t0 + milliseconds(5000)).empty()) << "robot 1 was heard 0.5 s ago, not 1 s";
  EXPECT_EQ(milliseconds(1000), rounds.silentFor(1, t0 + milliseconds(5500)));
  EXPECT_EQ(std::vector<std::size_t>{1}, rounds.dropOuts(t0 + milliseconds(5500)));
  EXPECT_TRUE(rounds.dropOuts(t0 + milliseconds(9000)).empty()) << "a robot drops out once";
  EXPECT_TRUE(rounds.roundComplete()) << "the round goes on without the silent robot";
  rounds.take(0);
  rounds.take(2);

  // Heard again: it takes part from the next round on, which then waits for it.
  EXPECT_TRUE(rounds.heard(1, t0 + milliseconds(9500)));
  EXPECT_FALSE(rounds.heard(1, t0 + milliseconds(9600))) << "it was back already";
  rounds.hold(0);
  rounds.hold(2);
  EXPECT_FALSE(rounds.roundComplete());
  rounds.hold(1);
  EXPECT_TRUE(rounds.roundComplete());
}

TEST(RobotRounds, WithoutSyncNothingIsHeldBack)
{
  EXPECT_FALSE(RobotRounds(4, false, kTimeout, kT0).holds());
  EXPECT_TRUE(RobotRounds(4, true, kTimeout, kT0).holds());
  EXPECT_THROW(RobotRounds(0, true, kTimeout, kT0), std::invalid_argument);
}
}  // namespace
