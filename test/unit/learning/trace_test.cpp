// The trace as the core makes it: what an update reports, how a step and a table are written,
// the state names a config gives, the replay file's checks, and the session's trace.
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/learning/trace.h"
#include "cartpole_qlearning/learning/transition_replay.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using namespace cartpole_qlearning;

namespace
{
TrainingConfig tutorialConfig()
{
  const auto source = loadYamlParameters(CARTPOLE_CONFIG_DIR "/tutorial_4_states.yaml");
  refuseUnknownSections(*source);
  return readTrainingConfig(*source);
}

std::string replayError(const std::string& text, const std::vector<std::string>& names)
{
  try
  {
    parseReplay(text, "mine.yaml", names, 2);
  }
  catch (const ReplayError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Trace, UpdateReportsOldValueTargetAndNewValue)
{
  AgentParams params;
  params.discretiser.bins = {{1, 1, 1, 4}};
  params.gamma = 0.9;
  QLearningAgent agent(params, 0);
  agent.table().at(2, 1) = 4.0;
  agent.table().at(0, 0) = 1.0;
  QUpdate u = agent.update(0, 0, 1.0, 2, false, 0.5);
  EXPECT_EQ(1.0, u.old_value);
  EXPECT_EQ(4.0, u.next_max);
  EXPECT_DOUBLE_EQ(1.0 + 0.9 * 4.0, u.target);
  EXPECT_DOUBLE_EQ(1.0 + 0.5 * (4.6 - 1.0), u.new_value);
  EXPECT_EQ(agent.table().at(0, 0), u.new_value);
  // Into a terminal state: the reward alone, whatever the next row holds.
  u = agent.update(1, 1, -1.0, 2, true, 0.5);
  EXPECT_EQ(-1.0, u.target);
  EXPECT_EQ(0.0, u.next_max);
  EXPECT_EQ(-0.5, u.new_value);
}

TEST(Trace, AStepAndATableAreWrittenAsTheTutorialWorksThem)
{
  const TrainingConfig config = tutorialConfig();
  const std::vector<std::string> names = stateNames(config.agent);
  ASSERT_EQ((std::vector<std::string>{"S1 tilted left", "S0 upright", "S2 tilted right", "S3 fallen"}), names);
  TraceStep step;
  step.episode = 2;
  step.step = 1;
  step.state = 1;
  step.action = 1;
  step.reward = 1.0;
  step.next_state = 0;
  step.alpha = 0.5;
  step.gamma = 0.9;
  step.update = QUpdate{-0.25, 0.725, 1.6525, 0.70125};
  EXPECT_EQ(
      "episode 2 step 1: S0 upright --A1 (+10 N)--> S1 tilted left, r = 1; target = 1 + 0.9 * 0.725 = 1.6525; "
      "Q(S0 upright, A1) = -0.25 + 0.5 * (1.6525 - (-0.25)) = 0.70125",
      traceLine(step, names, config.agent.actions));
  step.terminal = true;
  step.reward = -1.0;
  step.update = QUpdate{0.5, 0.0, -1.0, -0.25};
  EXPECT_EQ(
      "episode 2 step 1: S0 upright --A1 (+10 N)--> S3 fallen (terminal), r = -1; target = -1 (no future); "
      "Q(S0 upright, A1) = 0.5 + 0.5 * (-1 - 0.5) = -0.25",
      traceLine(step, names, config.agent.actions));

  QTable table(config.agent.discretiser, config.agent.actions);
  table.at(0, 0) = 1.71037015625;
  table.at(1, 1) = -0.25;
  EXPECT_EQ(
      "  state            A0 (-10 N)      A1 (+10 N)\n"
      "  S1 tilted left   1.71037015625   0\n"
      "  S0 upright       0               -0.25\n"
      "  S2 tilted right  0               0\n"
      "  S3 fallen        0               0               (terminal: no future, Q = 0)",
      qTableText(table, names));
}

TEST(Trace, DefaultNamesAreRowNumbersAndFallen)
{
  AgentParams params;
  params.discretiser.bins = {{1, 1, 2, 1}};
  EXPECT_EQ((std::vector<std::string>{"S0", "S1", "fallen"}), stateNames(params));
}

TEST(Trace, StateNamesMustNameEveryRowAndTheTerminalStateOnceEach)
{
  AgentParams params;
  params.discretiser.bins = {{1, 1, 3, 1}};
  params.state_names = {"a", "b", "c"};
  EXPECT_NE(std::string::npos, params.validate().find("state_names lists 3 names")) << params.validate();
  params.state_names = {"a", "b", "c", "b"};
  EXPECT_NE(std::string::npos, params.validate().find("state_names[3] = 'b'")) << params.validate();
  params.state_names = {"a", " b", "c", "d"};
  EXPECT_NE(std::string::npos, params.validate().find("state_names[1]")) << params.validate();
  params.state_names = {"a", "b", "c", "d"};
  EXPECT_EQ("", params.validate());

  // From a config file, with the key named.
  const auto source = parseYamlParameters("learning: {bins: [1, 1, 3, 1], state_names: [a, b]}", "names.yaml");
  EXPECT_THROW(readTrainingConfig(*source), ConfigError);
  try
  {
    readTrainingConfig(*source);
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("names.yaml: learning/state_names lists 2 names"))
        << e.what();
  }
}

TEST(Trace, ReplayFileMistakesNameTheirLine)
{
  const std::vector<std::string> names = stateNames(tutorialConfig().agent);
  const std::string head = "# mine\ntransitions:\n  - [S0 upright, A1, 1, S1 tilted left]\n";
  EXPECT_EQ(
      "mine.yaml line 4: unknown state 'S4' (this config's states: S1 tilted left, S0 upright, S2 tilted "
      "right, S3 fallen)",
      replayError(head + "  - [S4, A1, 1, S1 tilted left]\n", names));
  EXPECT_NE(std::string::npos,
            replayError(head + "  - [S0 upright, 7, 1, S1 tilted left]\n", names).find("line 4: action '7' is out"));
  EXPECT_NE(std::string::npos,
            replayError(head + "  - [S0 upright, Ax, 1, S1 tilted left]\n", names).find("line 4: action 'Ax'"));
  EXPECT_NE(std::string::npos,
            replayError(head + "  - [S0 upright, A0, .nan, S1 tilted left]\n", names).find("line 4: reward '.nan'"));
  EXPECT_NE(std::string::npos,
            replayError(head + "  - [S0 upright, A0, 1, [S1]]\n", names).find("line 4: '[S1]' is not allowed"));
  EXPECT_NE(std::string::npos, replayError("transitions: []\n", names).find("must be a non-empty list"));
  EXPECT_NE(std::string::npos, replayError("transitions: [\n", names).find("not valid YAML"));
  EXPECT_EQ("", replayError(head + "  - [S1 tilted left, 0, -2.5e-1, S3 fallen]\n", names));
}

TEST(Trace, ReplayLearnsFromItsTransitionsAndCountsStepsAndEpisodes)
{
  const TrainingConfig config = tutorialConfig();
  const std::vector<std::string> names = stateNames(config.agent);
  const auto transitions = loadReplay(CARTPOLE_CONFIG_DIR "/tutorial_10_steps.yaml", names, 2);
  ASSERT_EQ(10u, transitions.size());
  EXPECT_TRUE(transitions[2].terminal);
  EXPECT_EQ(11, transitions[2].line);
  QLearningAgent agent(config.agent, 0);
  std::vector<TraceStep> steps;
  std::vector<std::uint64_t> ended;
  replayTransitions(
      agent, transitions, [&](const ReplayTransition&, const TraceStep& s) { steps.push_back(s); },
      [&](std::uint64_t episode) { ended.push_back(episode); });
  ASSERT_EQ(10u, steps.size());
  EXPECT_EQ((std::vector<std::uint64_t>{1}), ended);
  EXPECT_EQ(2u, steps[3].episode);
  EXPECT_EQ(1u, steps[3].step);
  EXPECT_EQ(7u, steps[9].step);
  EXPECT_NEAR(1.117003125, agent.table().at(1, 0), 1e-15);
  EXPECT_NEAR(1.71037015625, agent.table().at(0, 0), 1e-15);
  EXPECT_EQ(10u, agent.table().steps);
  EXPECT_EQ(1u, agent.table().episodes);
}

// While training, one traced step per update, numbered as the episodes' summaries number them,
// each reporting the value the table then holds.
TEST(Trace, TheSessionTracesEveryUpdateOfEveryEpisode)
{
  TrainingConfig config = tutorialConfig();
  config.limits.max_episodes = 4;
  HeadlessTrainer trainer(config, 5);
  std::vector<TraceStep> steps;
  trainer.session().setTrace([&](std::size_t robot, const TraceStep& s) {
    EXPECT_EQ(0u, robot);
    EXPECT_EQ(trainer.session().table().at(s.state, s.action), s.update.new_value);
    steps.push_back(s);
  });
  std::vector<EpisodeSummary> summaries;
  const TrainingResult result = trainer.run([&](const EpisodeSummary& s) { summaries.push_back(s); });
  ASSERT_EQ(result.steps, steps.size());
  std::size_t i = 0;
  for (const EpisodeSummary& summary : summaries)
  {
    for (unsigned k = 1; k <= summary.steps; ++k, ++i)
    {
      EXPECT_EQ(summary.episode, steps[i].episode);
      EXPECT_EQ(k, steps[i].step);
      EXPECT_EQ(k == summary.steps && summary.terminated, steps[i].terminal);
      EXPECT_EQ(0.5, steps[i].alpha);
      EXPECT_EQ(0.9, steps[i].gamma);
    }
  }
}
