#include "cartpole_qlearning/learning/schedule.h"

#include <gtest/gtest.h>

#include <cmath>

using cartpole_qlearning::Schedule;
using cartpole_qlearning::ScheduleParams;
using cartpole_qlearning::ScheduleType;

namespace
{
ScheduleParams params(ScheduleType type, double start, double min)
{
  ScheduleParams p;
  p.type = type;
  p.start = start;
  p.min = min;
  return p;
}
}  // namespace

TEST(Schedule, ConstantNeverChanges)
{
  const Schedule s(params(ScheduleType::Constant, 0.3, 0.0));
  EXPECT_EQ(0.3, s.value(0));
  EXPECT_EQ(0.3, s.value(1000000));
}

TEST(Schedule, LinearReachesMinAfterDecayEpisodes)
{
  ScheduleParams p = params(ScheduleType::Linear, 1.0, 0.1);
  p.decay_episodes = 100;
  const Schedule s(p);
  EXPECT_DOUBLE_EQ(1.0, s.value(0));
  EXPECT_DOUBLE_EQ(0.55, s.value(50));
  EXPECT_DOUBLE_EQ(0.1, s.value(100));
  EXPECT_DOUBLE_EQ(0.1, s.value(5000));
}

TEST(Schedule, ExponentialMultipliesEachEpisodeDownToMin)
{
  ScheduleParams p = params(ScheduleType::Exponential, 1.0, 0.01);
  p.decay_rate = 0.5;
  const Schedule s(p);
  EXPECT_DOUBLE_EQ(1.0, s.value(0));
  EXPECT_DOUBLE_EQ(0.25, s.value(2));
  EXPECT_DOUBLE_EQ(0.015625, s.value(6));
  EXPECT_DOUBLE_EQ(0.01, s.value(7));  // 0.0078125 floored
}

TEST(Schedule, LogIsTheTutorials)
{
  // max(min, min(1, 1 - log10((e + 1) / 25))): 1.0 for the first 25 episodes, then down.
  ScheduleParams p = params(ScheduleType::Log, 1.0, 0.01);
  p.log_divisor = 25;
  const Schedule s(p);
  EXPECT_DOUBLE_EQ(1.0, s.value(0));
  EXPECT_DOUBLE_EQ(1.0, s.value(24));
  EXPECT_DOUBLE_EQ(1.0 - std::log10(26.0 / 25.0), s.value(25));
  EXPECT_NEAR(0.39794, s.value(99), 1e-5);  // 1 - log10(4)
  EXPECT_DOUBLE_EQ(0.01, s.value(250));
}

TEST(Schedule, LogNeverExceedsStart)
{
  ScheduleParams p = params(ScheduleType::Log, 0.5, 0.1);
  const Schedule s(p);
  EXPECT_DOUBLE_EQ(0.5, s.value(0));
}

TEST(Schedule, BadParametersAreRefusedWithTheirName)
{
  ScheduleParams p = params(ScheduleType::Log, 1.5, 0.1);
  EXPECT_NE(std::string::npos, p.validate().find("start = 1.5")) << p.validate();
  p = params(ScheduleType::Linear, 0.5, 0.6);
  EXPECT_NE(std::string::npos, p.validate().find("min = 0.6")) << p.validate();
  p = params(ScheduleType::Exponential, 1.0, 0.0);
  p.decay_rate = 1.5;
  EXPECT_NE(std::string::npos, p.validate().find("decay_rate = 1.5")) << p.validate();
  EXPECT_THROW(Schedule s(p), std::invalid_argument);
  EXPECT_THROW(cartpole_qlearning::scheduleTypeFromString("cosine"), std::invalid_argument);
}
