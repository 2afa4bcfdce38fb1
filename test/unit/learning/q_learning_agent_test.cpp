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

TEST(QLearningAgent, AnEnsembleTeachesTheTableWhoseTurnItIsAndGivesTheirMean)
{
  AgentParams p = tutorialParams();
  p.ensemble = 2;
  QLearningAgent agent(p, 0);
  ASSERT_EQ(2u, agent.ensembleTables().size());
  // Episode 0 is the first table's: Q(S0, A1) = 0 + 0.5 (1 - 0) there, half of it in the mean.
  agent.learnWith(0);
  agent.update(0, 1, 1.0, 3, true, 0.5);
  EXPECT_EQ(0.5, agent.ensembleTables()[0].at(0, 1));
  EXPECT_EQ(0.0, agent.ensembleTables()[1].at(0, 1));
  EXPECT_EQ(0.25, agent.table().at(0, 1));
  // Episode 1 is the second's, which bootstraps from its own values (none yet), not the mean's.
  agent.learnWith(1);
  const auto update = agent.update(1, 0, 0.0, 0, false, 1.0);
  EXPECT_EQ(0.0, update.next_max);
  EXPECT_EQ(0.0, agent.table().at(1, 0));
  agent.update(0, 0, 2.0, 3, true, 0.5);
  EXPECT_EQ(1.0, agent.ensembleTables()[1].at(0, 0));
  EXPECT_EQ(0.5, agent.table().at(0, 0));
  // Episode 2 is the first table's again: its own max at S0 is 0.5 (A1), the mean's 0.5 too, but
  // the second table's 1.0 (A0) is not its.
  agent.learnWith(2);
  EXPECT_EQ(0.9 * 0.5, agent.update(1, 0, 0.0, 0, false, 1.0).target);
  EXPECT_EQ(0.45, agent.ensembleTables()[0].at(1, 0));
  EXPECT_EQ(0.225, agent.table().at(1, 0));
  // Each explores on its own values; the mean (what runs greedily) on both.
  agent.learnWith(0);
  EXPECT_EQ(1u, agent.selectAction(0, 0.0));
  agent.learnWith(1);
  EXPECT_EQ(0u, agent.selectAction(0, 0.0));
  EXPECT_EQ(0u, agent.greedyAction(0));  // mean: A0 0.5 > A1 0.25
}

TEST(QLearningAgent, AnEnsemblesMeanFollowsEveryUpdateOfTilesAndTraces)
{
  AgentParams p;
  p.features = cartpole_qlearning::FeatureKind::Tiles;
  p.tilings = 4;
  p.tiles = {{2, 2, 4, 4}};
  p.lambda = 0.8;
  p.ensemble = 3;
  QLearningAgent agent(p, 5);
  cartpole_qlearning::RandomStream draws(11, 0);
  cartpole_qlearning::EligibilityTraces traces;
  cartpole_qlearning::ActiveRows state;
  cartpole_qlearning::ActiveRows next;
  for (int episode = 0; episode < 30; ++episode)
  {
    agent.learnWith(static_cast<std::uint64_t>(episode));
    traces.clear();
    for (int step = 0; step < 20; ++step)
    {
      const auto random_state = [&] {
        cartpole_qlearning::CartPoleState s;
        for (int d = 0; d < 4; ++d)
          s[d] = draws.uniform(-1.0, 1.0);
        return s;
      };
      agent.activeRows(random_state(), state);
      agent.activeRows(random_state(), next);
      agent.update(state, agent.selectAction(state, 0.3), draws.uniform(-1.0, 1.0), next, step == 19, 0.3, &traces);
    }
  }
  const std::vector<QTable>& tables = agent.ensembleTables();
  double largest = 0.0;
  for (std::size_t row = 0; row < agent.table().stateCount(); ++row)
    for (std::size_t a = 0; a < 2; ++a)
    {
      const double mean = (tables[0].at(row, a) + tables[1].at(row, a) + tables[2].at(row, a)) / 3.0;
      EXPECT_NEAR(mean, agent.table().at(row, a), 1e-12) << "row " << row << ", action " << a;
      largest = std::max(largest, std::abs(tables[0].at(row, a) - tables[1].at(row, a)));
    }
  EXPECT_GT(largest, 0.01);  // the tables learnt apart
}

TEST(QLearningAgent, ALoadedTableIsEveryEnsembleTablesStart)
{
  AgentParams p = tutorialParams();
  p.ensemble = 2;
  QLearningAgent agent(p, 0);
  agent.learnWith(0);
  agent.update(0, 1, 1.0, 3, true, 0.5);
  QTable loaded(p.discretiser, p.actions);
  loaded.at(2, 0) = 3.0;
  EXPECT_EQ("", agent.replaceTable(loaded));
  for (const QTable& table : agent.ensembleTables())
  {
    EXPECT_EQ(3.0, table.at(2, 0));
    EXPECT_EQ(0.0, table.at(0, 1));
  }
  EXPECT_EQ(3.0, agent.table().at(2, 0));
}

TEST(QLearningAgent, AnEnsembleOutOfRangeIsRefusedAndOneTableHasNone)
{
  AgentParams p = tutorialParams();
  EXPECT_TRUE(QLearningAgent(p, 0).ensembleTables().empty());
  p.ensemble = 0;
  EXPECT_NE(std::string::npos, p.validate().find("ensemble = 0 is not allowed (must be in [1, 16])")) << p.validate();
  p.ensemble = 17;
  EXPECT_NE(std::string::npos, p.validate().find("ensemble = 17")) << p.validate();
  // The tables and their mean together hold no more than one table may: 4,000,000 values each, 5
  // of them with their mean; not 6.
  p.discretiser.bins = {1, 100, 100, 100};
  p.actions = {-10.0, -5.0, 5.0, 10.0};
  p.mirror = false;
  p.ensemble = 1;
  EXPECT_EQ("", p.validate());
  p.ensemble = 4;
  EXPECT_EQ("", p.validate());
  p.ensemble = 5;
  EXPECT_NE(std::string::npos,
            p.validate().find("ensemble = 5 with a table of 1000000 rows of 4 actions is not allowed (its 6 tables, "
                              "each and their mean, would hold more than the 20000000 values"))
      << p.validate();
}
