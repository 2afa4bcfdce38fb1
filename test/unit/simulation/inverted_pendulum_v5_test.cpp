// config/inverted_pendulum_v5.yaml against Gymnasium's own code for InvertedPendulum-v5: its
// reset (frame skip, reset noise on qpos and qvel) and its termination and reward, read from
// Gymnasium's files (GYMNASIUM_DIR, else ../shared/anchors/gymnasium beside the source tree). The
// tests skip, saying so, when those files are not there.
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/simulation/mujoco_engine.h"
#include "cartpole_qlearning/simulation/physics_engines.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/training_config.h"

#include <mujoco/mujoco.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <sys/stat.h>

using namespace cartpole_qlearning;

namespace
{
std::string gymnasiumDir()
{
  const char* given = std::getenv("GYMNASIUM_DIR");
  return given != nullptr ? given : CARTPOLE_GYMNASIUM_DIR;
}

bool exists(const std::string& path)
{
  struct stat info;
  return ::stat(path.c_str(), &info) == 0;
}

std::string readText(const std::string& path)
{
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class InvertedPendulumV5 : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = gymnasiumDir();
    if (!exists(dir_ + "/envs/mujoco/inverted_pendulum_v5.py"))
      GTEST_SKIP() << "Gymnasium's files are not at " << dir_
                   << ": set GYMNASIUM_DIR to a Gymnasium package folder (../shared/anchors/gymnasium has one)";
    ::setenv("GYMNASIUM_MUJOCO_ASSETS", (dir_ + "/envs/mujoco/assets").c_str(), 1);
    config_ = readTrainingConfig(*loadYamlParameters(CARTPOLE_CONFIG_DIR "/inverted_pendulum_v5.yaml"));
    code_ = readText(dir_ + "/envs/mujoco/inverted_pendulum_v5.py");
    registry_ = readText(dir_ + "/envs/__init__.py");
  }

  // Whether Gymnasium's code holds this text.
  bool says(const std::string& text) const
  {
    return code_.find(text) != std::string::npos;
  }

  std::string dir_;
  TrainingConfig config_;
  std::string code_;
  std::string registry_;
};

TEST_F(InvertedPendulumV5, ResetMatchesGymnasium)
{
  // frame_skip 2 of the model's timestep; reset_noise_scale 0.01 on every qpos and qvel.
  ASSERT_TRUE(says("frame_skip: int = 2,"));
  ASSERT_TRUE(says("reset_noise_scale: float = 0.01,"));
  ASSERT_TRUE(
      says("qpos = self.init_qpos + self.np_random.uniform(\n            size=self.model.nq, low=noise_low, "
           "high=noise_high"));
  ASSERT_TRUE(
      says("qvel = self.init_qvel + self.np_random.uniform(\n            size=self.model.nv, low=noise_low, "
           "high=noise_high"));
  EXPECT_EQ(config_.engine.model, dir_ + "/envs/mujoco/assets/inverted_pendulum.xml");
  const MujocoEngine engine(config_.engine, config_.physics.tau);
  EXPECT_EQ(2, engine.frameSkip());
  EXPECT_EQ(0.02, engine.model().opt.timestep);
  EXPECT_EQ(0.01, config_.start_state_bound);
  // init_qpos and init_qvel are the model's reference: zero, so a start is the draw itself.
  EXPECT_EQ(2, engine.model().nq);
  EXPECT_EQ(0.0, engine.model().qpos0[0]);
  EXPECT_EQ(0.0, engine.model().qpos0[1]);
  CartPoleSimulation sim = makeSimulation(config_.physics, config_.engine, config_.start_state_bound, 4);
  for (int episode = 0; episode < 20; ++episode)
  {
    const CartPoleState start = sim.resetRandom();
    EXPECT_LE(start.cwiseAbs().maxCoeff(), 0.01);
    const auto& used = dynamic_cast<const MujocoEngine&>(sim.engine());
    EXPECT_EQ(start[0], used.data().qpos[0]);
    EXPECT_EQ(start[2], used.data().qpos[1]);  // the hinge turns about +y: theta is its qpos
    EXPECT_EQ(start[1], used.data().qvel[0]);
    EXPECT_EQ(start[3], used.data().qvel[1]);
  }
  // The actions are ctrl within the model's ctrlrange (+-3) times its gear (100).
  EXPECT_EQ(100.0, engine.gear());
  EXPECT_EQ(300.0, engine.forceLimit());
  for (const double effort : config_.agent.actions)
    EXPECT_LE(std::fabs(effort), engine.forceLimit());
}

TEST_F(InvertedPendulumV5, TerminationAndRewardMatchGymnasium)
{
  // terminated = not finite, or |observation[1]| > 0.2 (observation = qpos, qvel: [1] is the hinge).
  ASSERT_TRUE(says("not np.isfinite(observation).all() or (np.abs(observation[1]) > 0.2)"));
  ASSERT_TRUE(says("reward = int(not terminated)"));
  ASSERT_TRUE(says("return np.concatenate([self.data.qpos, self.data.qvel]).ravel()"));
  const std::size_t registered = registry_.find("id=\"InvertedPendulum-v5\"");
  ASSERT_NE(registered, std::string::npos);
  const std::string entry = registry_.substr(registered, registry_.find(")", registered) - registered);
  ASSERT_NE(entry.find("max_episode_steps=1000,"), std::string::npos) << entry;
  ASSERT_NE(entry.find("reward_threshold=950.0,"), std::string::npos) << entry;

  const CartPoleTask task(config_.task);
  EXPECT_EQ(0.2, config_.task.thetaThresholdRad());
  for (const double sign : {1.0, -1.0})
  {
    EXPECT_FALSE(task.isTerminal(CartPoleState(0.0, 0.0, sign * 0.2, 0.0)));
    EXPECT_TRUE(task.isTerminal(CartPoleState(0.0, 0.0, sign * std::nextafter(0.2, 1.0), 0.0)));
    // Not on x: the slider's range (+-1 m) holds the cart, and v5 does not look at x.
    EXPECT_FALSE(task.isTerminal(CartPoleState(sign * 1.05, sign * 9.0, 0.0, sign * 9.0)));
  }
  const MujocoEngine engine(config_.engine, config_.physics.tau);
  EXPECT_EQ(1.0, engine.model().jnt_range[1]);
  EXPECT_GT(config_.task.x_threshold, 1.5);
  // +1 while not terminated, 0 on the step that terminates; 1000 steps; solved at 950. What the
  // returns and the solved window count, whatever reward the learner trains on.
  ASSERT_TRUE(config_.task.solved_reward.has_value());
  EXPECT_EQ(RewardScheme::Alive, config_.task.scoreReward());
  EXPECT_EQ(1.0, task.evaluate(CartPoleState(0.0, 0.0, 0.1, 0.0), 1, 0.0).score);
  EXPECT_EQ(1.0, task.evaluate(CartPoleState(0.9, 0.5, 0.1, 0.0), 1, 0.0).score);
  const StepOutcome fall = task.evaluate(CartPoleState(0.0, 0.0, -0.21, 0.0), 5, 0.0);
  EXPECT_TRUE(fall.terminated);
  EXPECT_EQ(0.0, fall.score);
  EXPECT_TRUE(task.evaluate(CartPoleState::Zero(), 1000, 0.0).truncated);
  EXPECT_FALSE(task.evaluate(CartPoleState::Zero(), 999, 0.0).truncated);
  EXPECT_EQ(1000u, config_.task.max_episode_steps);
  EXPECT_EQ(950.0, config_.task.solved_mean_return);
  EXPECT_EQ(100u, config_.task.solved_window);
}

TEST_F(InvertedPendulumV5, ABangBangRuleOnThetaHoldsTheModelsPole)
{
  // The sign convention on Gymnasium's model: pushing toward where the pole leans (and turns)
  // holds it upright for the whole 1000 steps.
  CartPoleSimulation sim = makeSimulation(config_.physics, config_.engine, config_.start_state_bound, 2);
  const CartPoleTask task(config_.task);
  for (int episode = 0; episode < 3; ++episode)
  {
    sim.resetRandom();
    unsigned steps = 0;
    while (steps < 1000 && !task.isTerminal(sim.state()))
    {
      const CartPoleState& s = sim.state();
      sim.step(s[2] + 0.2 * s[3] > 0.0 ? 30.0 : -30.0);
      ++steps;
    }
    EXPECT_EQ(1000u, steps) << "episode " << episode;
  }
}

TEST_F(InvertedPendulumV5, TheConfigSolvesV5OnSeed7ByGymnasiumsCriterion)
{
  // Trained on its own reward, judged by v5's: the mean of the last 100 episodes' steps alive
  // reaches 950 (seed 7: 237 episodes, 108,019 steps, about 3 s; docs/mujoco.md has seeds 0-9).
  HeadlessTrainer trainer(config_, 7);
  ReturnWindow alive(100);
  std::uint64_t steps = 0;
  const TrainingResult result = trainer.run([&](const EpisodeSummary& s) {
    // v5's return: a step counts while the pole is not past 0.2 rad, the falling step not.
    alive.push(static_cast<double>(s.steps) - (s.terminated ? 1.0 : 0.0));
    steps = s.total_steps;
  });
  EXPECT_TRUE(result.solved);
  EXPECT_TRUE(alive.full());
  EXPECT_GE(alive.mean(), 950.0);
  EXPECT_DOUBLE_EQ(alive.mean(), trainer.session().lastEpisode().mean_return_window);
  EXPECT_LE(steps, 200000u);
}

}  // namespace
