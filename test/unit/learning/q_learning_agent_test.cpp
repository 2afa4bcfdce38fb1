#include "cartpole_qlearning/learning/q_learning_agent.h"

#include <gtest/gtest.h>

#include <array>
#include <vector>

using cartpole_qlearning::AgentParams;
using cartpole_qlearning::QLearningAgent;
using cartpole_qlearning::QTable;

namespace
{
// The tutorial's toy problem as a table of 4 states (S0 upright, S1 tilted left, S2 tilted
// right, S3 fallen) and 2 actions: one discretised dimension of 4 bins, the others ignored.
AgentParams tutorialParams()
{
  AgentParams p;
  p.discretiser.bins = {{1, 1, 1, 4}};
  p.actions = {-10.0, 10.0};
  p.gamma = 0.9;
  return p;
}

struct Transition
{
  std::size_t state, action;
  double reward;
  std::size_t next;
  bool terminal;
};

using Table = std::array<std::array<double, 2>, 4>;

void expectTable(const Table& expected, const QTable& actual, int step)
{
  for (std::size_t s = 0; s < 4; ++s)
    for (std::size_t a = 0; a < 2; ++a)
      EXPECT_NEAR(expected[s][a], actual.at(s, a), 1e-12) << "after step " << step << ", Q(S" << s << ",A" << a << ")";
}
}  // namespace

TEST(QLearningAgent, TutorialWorkedExampleExactAfterEveryStep)
{
  QLearningAgent agent(tutorialParams(), 0);
  const double alpha = 0.5;
  const std::vector<Transition> transitions = {
      {0, 1, +1, 1, false}, {1, 0, +1, 0, false}, {0, 1, -1, 3, true},  {0, 1, +1, 1, false}, {1, 0, +1, 0, false},
      {0, 0, +1, 2, false}, {2, 1, +1, 0, false}, {0, 1, +1, 1, false}, {1, 0, +1, 0, false}, {0, 0, +1, 2, false},
  };
  // Exact values (as fractions: 29/40, 561/800, 18849/16000, 13049/16000, 441841/320000,
  // 10946369/6400000, 357441/320000), not the tutorial's rounded printout.
  const std::vector<Table> expected = {
      Table{{{0, 0.5}, {0, 0}, {0, 0}, {0, 0}}},
      Table{{{0, 0.5}, {0.725, 0}, {0, 0}, {0, 0}}},
      Table{{{0, -0.25}, {0.725, 0}, {0, 0}, {0, 0}}},
      Table{{{0, 0.70125}, {0.725, 0}, {0, 0}, {0, 0}}},
      Table{{{0, 0.70125}, {1.1780625, 0}, {0, 0}, {0, 0}}},
      Table{{{0.5, 0.70125}, {1.1780625, 0}, {0, 0}, {0, 0}}},
      Table{{{0.5, 0.70125}, {1.1780625, 0}, {0, 0.8155625}, {0, 0}}},
      Table{{{0.5, 1.380753125}, {1.1780625, 0}, {0, 0.8155625}, {0, 0}}},
      Table{{{0.5, 1.380753125}, {1.71037015625, 0}, {0, 0.8155625}, {0, 0}}},
      Table{{{1.117003125, 1.380753125}, {1.71037015625, 0}, {0, 0.8155625}, {0, 0}}},
  };
  expectTable(Table{}, agent.table(), 0);
  for (std::size_t i = 0; i < transitions.size(); ++i)
  {
    const Transition& t = transitions[i];
    agent.update(t.state, t.action, t.reward, t.next, t.terminal, alpha);
    expectTable(expected[i], agent.table(), static_cast<int>(i + 1));
  }
}

TEST(QLearningAgent, TerminalTransitionDoesNotBootstrapButOthersDo)
{
  QLearningAgent agent(tutorialParams(), 0);
  std::vector<double> values(8, 0.0);
  values[2 * 2 + 1] = 4.0;  // Q(S2, A1) = 4
  agent.table().setValues(values);
  agent.update(0, 0, 1.0, 2, false, 1.0);
  EXPECT_DOUBLE_EQ(1.0 + 0.9 * 4.0, agent.table().at(0, 0));
  agent.update(1, 0, 1.0, 2, true, 1.0);
  EXPECT_DOUBLE_EQ(1.0, agent.table().at(1, 0));
}

TEST(QLearningAgent, GreedyTiesGoToTheFirstAction)
{
  QLearningAgent agent(tutorialParams(), 0);
  EXPECT_EQ(0u, agent.greedyAction(0));
  agent.table().at(0, 1) = 0.1;
  EXPECT_EQ(1u, agent.greedyAction(0));
  for (int i = 0; i < 100; ++i)
    EXPECT_EQ(1u, agent.selectAction(0, 0.0));
}

TEST(QLearningAgent, FullExplorationPicksBothActionsEvenly)
{
  QLearningAgent agent(tutorialParams(), 3);
  agent.table().at(0, 1) = 5.0;
  int ones = 0;
  const int draws = 10000;
  for (int i = 0; i < draws; ++i)
    ones += static_cast<int>(agent.selectAction(0, 1.0));
  EXPECT_NEAR(0.5, static_cast<double>(ones) / draws, 0.03);
}

TEST(QLearningAgent, SameSeedSameExplorationOtherSeedOther)
{
  QLearningAgent a(tutorialParams(), 42);
  QLearningAgent b(tutorialParams(), 42);
  QLearningAgent c(tutorialParams(), 43);
  std::vector<std::size_t> sa, sb, sc;
  for (int i = 0; i < 64; ++i)
  {
    sa.push_back(a.selectAction(0, 0.5));
    sb.push_back(b.selectAction(0, 0.5));
    sc.push_back(c.selectAction(0, 0.5));
  }
  EXPECT_EQ(sa, sb);
  EXPECT_NE(sa, sc);
}

TEST(QLearningAgent, ReplaceTableRefusesAnotherShapeAndKeepsTheLiveTable)
{
  QLearningAgent agent(tutorialParams(), 0);
  agent.table().at(3, 1) = 2.5;
  AgentParams other = tutorialParams();
  other.discretiser.bins = {{1, 1, 2, 2}};
  const std::string mismatch = agent.replaceTable(QTable(other.discretiser, other.actions));
  EXPECT_NE(std::string::npos, mismatch.find("bins")) << mismatch;
  EXPECT_EQ(2.5, agent.table().at(3, 1));

  QTable three_actions(tutorialParams().discretiser, {-10.0, 0.0, 10.0});
  EXPECT_NE(std::string::npos, agent.replaceTable(three_actions).find("actions"));
  EXPECT_EQ(2.5, agent.table().at(3, 1));

  QTable same(tutorialParams().discretiser, tutorialParams().actions);
  same.at(0, 0) = 7.0;
  EXPECT_EQ("", agent.replaceTable(same));
  EXPECT_EQ(7.0, agent.table().at(0, 0));
  EXPECT_EQ(0.0, agent.table().at(3, 1));
}

TEST(QLearningAgent, BadParametersAreRefusedWithTheirName)
{
  AgentParams p = tutorialParams();
  p.gamma = 1.5;
  EXPECT_NE(std::string::npos, p.validate().find("gamma = 1.5")) << p.validate();
  EXPECT_THROW(QLearningAgent agent(p, 0), std::invalid_argument);
  p = tutorialParams();
  p.actions.clear();
  EXPECT_NE(std::string::npos, p.validate().find("actions")) << p.validate();
  p = tutorialParams();
  p.epsilon.min = 2.0;
  EXPECT_NE(std::string::npos, p.validate().find("epsilon/min = 2")) << p.validate();
}

TEST(QLearningAgent, TracesCarryATdErrorBackToTheStatesBeforeIt)
{
  AgentParams p = tutorialParams();
  p.lambda = 0.5;
  QLearningAgent agent(p, 0);
  cartpole_qlearning::EligibilityTraces traces;
  // S0 -A0-> S1 (reward 0), then S1 -A0-> S2 (reward 1), alpha 1, gamma 0.9.
  agent.update(cartpole_qlearning::ActiveRows::single(0), 0, 0.0, cartpole_qlearning::ActiveRows::single(1), false, 1.0,
               &traces);
  EXPECT_DOUBLE_EQ(0.0, agent.table().at(0, 0));
  EXPECT_DOUBLE_EQ(0.9 * 0.5, traces.trace(0 * 2 + 0));  // faded by gamma * lambda
  agent.update(cartpole_qlearning::ActiveRows::single(1), 0, 1.0, cartpole_qlearning::ActiveRows::single(2), false, 1.0,
               &traces);
  // The error 1 moves Q(S1,A0) by 1 and Q(S0,A0), still traced, by its trace 0.45: one-step
  // Q-learning would have left it at 0.
  EXPECT_DOUBLE_EQ(1.0, agent.table().at(1, 0));
  EXPECT_DOUBLE_EQ(0.45, agent.table().at(0, 0));
  EXPECT_DOUBLE_EQ(0.0, agent.table().at(0, 1));  // never taken: no trace
  EXPECT_DOUBLE_EQ(0.0, agent.table().at(1, 1));
  // A terminal transition ends the traces.
  agent.update(cartpole_qlearning::ActiveRows::single(2), 1, 0.0, cartpole_qlearning::ActiveRows::single(3), true, 1.0,
               &traces);
  EXPECT_EQ(0u, traces.size());
}

TEST(QLearningAgent, WithoutLambdaTheTracesAreNotUsed)
{
  QLearningAgent agent(tutorialParams(), 0);
  cartpole_qlearning::EligibilityTraces traces;
  agent.update(cartpole_qlearning::ActiveRows::single(0), 0, 0.0, cartpole_qlearning::ActiveRows::single(1), false, 1.0,
               &traces);
  agent.update(cartpole_qlearning::ActiveRows::single(1), 0, 1.0, cartpole_qlearning::ActiveRows::single(2), false, 1.0,
               &traces);
  EXPECT_DOUBLE_EQ(0.0, agent.table().at(0, 0));
  EXPECT_EQ(0u, traces.size());
}

TEST(QLearningAgent, AVisitedTraceIsReplacedNotAccumulated)
{
  cartpole_qlearning::EligibilityTraces traces;
  const auto s0 = cartpole_qlearning::ActiveRows::single(0);
  traces.visit(s0, 1, 2, 8);
  traces.decay(0.5);
  traces.visit(s0, 1, 2, 8);
  EXPECT_DOUBLE_EQ(1.0, traces.trace(1));
  traces.decay(0.5);
  traces.decay(0.5);
  EXPECT_DOUBLE_EQ(0.25, traces.trace(1));
  // Below the floor (0.01) a trace is dropped.
  for (int i = 0; i < 5; ++i)
    traces.decay(0.5);
  EXPECT_EQ(0u, traces.size());
  EXPECT_DOUBLE_EQ(0.0, traces.trace(1));
}

TEST(QLearningAgent, AnInitialValueIsEveryQBeforeLearning)
{
  AgentParams p;
  p.features = cartpole_qlearning::FeatureKind::Tiles;
  p.tilings = 4;
  p.actions = {-10.0, 0.0, 10.0};
  p.initial_value = 30.0;
  QLearningAgent agent(p, 0);
  cartpole_qlearning::ActiveRows rows;
  agent.activeRows(cartpole_qlearning::CartPoleState(0.1, -0.2, 0.05, 0.3), rows);
  for (std::size_t a = 0; a < 3; ++a)
    EXPECT_DOUBLE_EQ(30.0, agent.value(rows, a));
}

TEST(QLearningAgent, WarpedFeaturesAreFinerNearZero)
{
  AgentParams p;
  p.discretiser.bins = {{1, 1, 4, 1}};
  p.discretiser.lower[2] = -1.0;
  p.discretiser.upper[2] = 1.0;
  const QLearningAgent uniform(p, 0);
  p.warp[2] = 2.0;
  const QLearningAgent warped(p, 0);
  const auto row = [](const QLearningAgent& agent, double theta) {
    cartpole_qlearning::ActiveRows rows;
    agent.activeRows(cartpole_qlearning::CartPoleState(0.0, 0.0, theta, 0.0), rows);
    return rows.rows[0];
  };
  // Uniform: [0, 0.5) is one bin. Warped by 2: 0.1 is seen at sqrt(0.1) = 0.32, 0.4 at 0.63.
  EXPECT_EQ(row(uniform, 0.1), row(uniform, 0.4));
  EXPECT_NE(row(warped, 0.1), row(warped, 0.4));
  EXPECT_EQ(3u, row(warped, 0.3));   // sqrt(0.3) = 0.55
  EXPECT_EQ(0u, row(warped, -0.3));  // and its mirror image
  // A warped dimension's bounds must be symmetric about 0.
  p.discretiser.lower[2] = -0.5;
  EXPECT_NE(std::string::npos, p.validate().find("warp[2] = 2")) << p.validate();
}

TEST(QLearningAgent, LambdaAndDecisionStepsOutOfRangeAreRefused)
{
  AgentParams p = tutorialParams();
  p.lambda = 1.5;
  EXPECT_NE(std::string::npos, p.validate().find("lambda = 1.5")) << p.validate();
  p = tutorialParams();
  p.decision_steps = 0;
  EXPECT_NE(std::string::npos, p.validate().find("decision_steps = 0")) << p.validate();
}
