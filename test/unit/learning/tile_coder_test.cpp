#include "cartpole_qlearning/learning/q_learning_agent.h"
#include "cartpole_qlearning/common/random.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/learning/tile_coder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace cartpole_qlearning;

namespace
{
// Tiles along theta_dot only, over [lower, upper], the other dimensions ignored.
TileCoderParams thetaDotOnly(unsigned tilings, unsigned tiles, double lower, double upper)
{
  TileCoderParams p;
  p.tilings = tilings;
  p.tiles = {{1, 1, 1, tiles}};
  p.lower[3] = lower;
  p.upper[3] = upper;
  return p;
}

std::vector<std::uint32_t> active(const TileCoder& coder, const CartPoleState& state)
{
  std::vector<std::uint32_t> tiles(coder.tilings());
  coder.activeTiles(state, tiles.data());
  return tiles;
}

std::vector<std::uint32_t> activeAt(const TileCoder& coder, double theta_dot)
{
  return active(coder, CartPoleState(0.0, 0.0, 0.0, theta_dot));
}

using Tiles = std::vector<std::uint32_t>;
}  // namespace

// Two tilings of two tiles over [-1, 1]: tiling 0's edges at -1, 0, 1; tiling 1 displaced by
// half a tile towards lower values, edges at -1.5, -0.5, 0.5. Each tiling has three tiles along
// the dimension (rows 0-2 and 3-5).
TEST(TileCoder, ValuesOnAnEdgeGoToTheTileThatStartsThere)
{
  const TileCoder coder(thetaDotOnly(2, 2, -1.0, 1.0));
  ASSERT_EQ(3u, coder.tilesPerTiling());
  ASSERT_EQ(6u, coder.tileCount());
  EXPECT_EQ((Tiles{0, 3}), activeAt(coder, -1.0));
  EXPECT_EQ((Tiles{0, 3}), activeAt(coder, std::nextafter(-0.5, -1.0)));
  EXPECT_EQ((Tiles{0, 4}), activeAt(coder, -0.5));
  EXPECT_EQ((Tiles{0, 4}), activeAt(coder, std::nextafter(0.0, -1.0)));
  EXPECT_EQ((Tiles{1, 4}), activeAt(coder, 0.0));
  EXPECT_EQ((Tiles{1, 4}), activeAt(coder, std::nextafter(0.5, 0.0)));
  EXPECT_EQ((Tiles{1, 5}), activeAt(coder, 0.5));
  EXPECT_EQ((Tiles{1, 5}), activeAt(coder, std::nextafter(1.0, 0.0)));
}

TEST(TileCoder, ValuesOutsideTheBoundsAreClippedToTheEdgeTiles)
{
  const TileCoder coder(thetaDotOnly(2, 2, -1.0, 1.0));
  EXPECT_EQ((Tiles{0, 3}), activeAt(coder, -1.5));
  EXPECT_EQ((Tiles{0, 3}), activeAt(coder, -1e300));
  EXPECT_EQ((Tiles{0, 3}), activeAt(coder, -std::numeric_limits<double>::infinity()));
  EXPECT_EQ((Tiles{0, 3}), activeAt(coder, std::numeric_limits<double>::quiet_NaN()));
  // At and above upper: the tile holding the values just below it, in every tiling (tiling 0's
  // extra tile, row 2, is never used).
  EXPECT_EQ((Tiles{1, 5}), activeAt(coder, 1.0));
  EXPECT_EQ((Tiles{1, 5}), activeAt(coder, 7.0));
  EXPECT_EQ((Tiles{1, 5}), activeAt(coder, std::numeric_limits<double>::infinity()));
}

// Sutton and Barto's asymmetric offsets: along the k-th used dimension tiling i is displaced by
// i * (2k + 1) / tilings of a tile (modulo a tile), so the tilings' edges spread evenly and
// differently in each dimension. Over [0, 8] with 2 tiles of 4 and 4 tilings, a displacement of
// o quarters moves tiling i's middle edge from 4 to 4 - o.
TEST(TileCoder, EachTilingIsDisplacedByItsOddMultipleOfAFractionOfATile)
{
  TileCoderParams p;
  p.tilings = 4;
  p.tiles = {{1, 1, 2, 2}};
  p.lower = {{0.0, 0.0, 0.0, 0.0}};
  p.upper = {{1.0, 1.0, 8.0, 8.0}};
  const TileCoder coder(p);
  const unsigned theta_offsets[] = {0, 1, 2, 3};      // i * 1 mod 4
  const unsigned theta_dot_offsets[] = {0, 3, 2, 1};  // i * 3 mod 4
  for (unsigned i = 0; i < 4; ++i)
  {
    EXPECT_EQ(theta_offsets[i], coder.offset(i, 2)) << "tiling " << i;
    EXPECT_EQ(theta_dot_offsets[i], coder.offset(i, 3)) << "tiling " << i;
    EXPECT_EQ(0u, coder.offset(i, 0)) << "an ignored dimension has no offset";
  }
  const std::size_t per_tiling = coder.tilesPerTiling();
  ASSERT_EQ(9u, per_tiling);  // 3 x 3: one tile more than 2 along each used dimension
  for (unsigned i = 0; i < 4; ++i)
  {
    // The edge along theta (theta_dot held at 0.5, inside its first tile in every tiling).
    const double theta_edge = 4.0 - theta_offsets[i];
    const std::uint32_t below = active(coder, CartPoleState(0, 0, std::nextafter(theta_edge, 0.0), 0.5))[i];
    const std::uint32_t at = active(coder, CartPoleState(0, 0, theta_edge, 0.5))[i];
    EXPECT_EQ(below + 3, at) << "tiling " << i << ": theta's edge is not at " << theta_edge;  // stride of theta: 3
    // The edge along theta_dot.
    const double theta_dot_edge = 4.0 - theta_dot_offsets[i];
    const std::uint32_t below_dot = active(coder, CartPoleState(0, 0, 0.5, std::nextafter(theta_dot_edge, 0.0)))[i];
    const std::uint32_t at_dot = active(coder, CartPoleState(0, 0, 0.5, theta_dot_edge))[i];
    EXPECT_EQ(below_dot + 1, at_dot) << "tiling " << i << ": theta_dot's edge is not at " << theta_dot_edge;
    // Each tiling's tiles are its own rows.
    EXPECT_GE(at, i * per_tiling);
    EXPECT_LT(at, (i + 1) * per_tiling);
  }
}

TEST(TileCoder, TheOddNumbersFollowTheUsedDimensionsInOrder)
{
  TileCoderParams p;
  p.tilings = 8;
  p.tiles = {{2, 2, 6, 12}};
  const TileCoder coder(p);
  for (unsigned i = 0; i < 8; ++i)
  {
    EXPECT_EQ(i * 1 % 8, coder.offset(i, 0));
    EXPECT_EQ(i * 3 % 8, coder.offset(i, 1));
    EXPECT_EQ(i * 5 % 8, coder.offset(i, 2));
    EXPECT_EQ(i * 7 % 8, coder.offset(i, 3));
  }
  EXPECT_EQ(3u * 3u * 7u * 13u, coder.tilesPerTiling());
  EXPECT_EQ(8u * 3u * 3u * 7u * 13u, coder.tileCount());
}

TEST(TileCoder, AnIgnoredDimensionChangesNothingAndNearbyStatesShareTiles)
{
  const TileCoder coder;  // 8 tilings of [1, 1, 6, 12]
  const Tiles here = active(coder, CartPoleState(0.0, 0.0, 0.01, 0.1));
  EXPECT_EQ(here, active(coder, CartPoleState(100.0, -50.0, 0.01, 0.1)));
  // A small step changes the tile of only some tilings: that is the generalisation.
  const Tiles near = active(coder, CartPoleState(0.0, 0.0, 0.01 + 0.07 / 8, 0.1));
  std::size_t shared = 0;
  for (std::size_t i = 0; i < here.size(); ++i)
    shared += here[i] == near[i];
  EXPECT_GT(shared, 0u);
  EXPECT_LT(shared, here.size());
}

TEST(TileCoder, BadParametersAreRefusedWithTheField)
{
  TileCoderParams p;
  p.tilings = 0;
  EXPECT_NE(std::string::npos, p.validate().find("tilings = 0")) << p.validate();
  p.tilings = kMaxTilings + 1;
  EXPECT_NE(std::string::npos, p.validate().find("tilings = 65")) << p.validate();
  p = TileCoderParams();
  p.tiles[2] = 0;
  EXPECT_NE(std::string::npos, p.validate().find("tiles[2] (theta) = 0")) << p.validate();
  p = TileCoderParams();
  p.lower[3] = p.upper[3];
  EXPECT_NE(std::string::npos, p.validate().find("lower_bounds[3]")) << p.validate();
  p = TileCoderParams();
  p.tilings = 64;
  p.tiles = {{20, 20, 20, 20}};
  EXPECT_NE(std::string::npos, p.validate().find("more than the 10000000 allowed")) << p.validate();
  EXPECT_THROW(TileCoder{p}, std::invalid_argument);
}

namespace
{
// Two tilings of two tiles of theta_dot over [-1, 1] (as above), 2 actions, gamma 0.9.
AgentParams twoTilings()
{
  AgentParams p;
  p.features = FeatureKind::Tiles;
  p.tilings = 2;
  p.tiles = {{1, 1, 1, 2}};
  p.discretiser.lower[3] = -1.0;
  p.discretiser.upper[3] = 1.0;
  p.gamma = 0.9;
  return p;
}
}  // namespace

TEST(TileCodedAgent, QIsTheSumOfTheActiveTilesWeights)
{
  QLearningAgent agent(twoTilings(), 0);
  ASSERT_EQ(6u, agent.table().stateCount());
  agent.table().at(1, 0) = 1.5;  // tiling 0, tile 1
  agent.table().at(4, 0) = 2.0;  // tiling 1, tile 1
  agent.table().at(1, 1) = -1.0;
  agent.table().at(4, 1) = 0.25;
  agent.table().at(5, 1) = 10.0;  // not active at 0.25
  ActiveRows s;
  agent.activeRows(CartPoleState(0.0, 0.0, 0.0, 0.25), s);
  ASSERT_EQ(2u, s.count);
  EXPECT_EQ(1u, s.rows[0]);
  EXPECT_EQ(4u, s.rows[1]);
  EXPECT_EQ(3.5, agent.value(s, 0));
  EXPECT_EQ(-0.75, agent.value(s, 1));
  EXPECT_EQ(0u, agent.greedyAction(s));
  agent.table().at(4, 1) = 4.75;  // Q(s, 1) = 3.75 > 3.5
  EXPECT_EQ(1u, agent.greedyAction(s));
}

// Q(s,a0) = 1.5 + 2.0 = 3.5 over rows 1 and 4; s' (theta_dot 0.75) activates rows 1 and 5 with
// Q(s',a0) = 1.5 + 0.5 = 2 and Q(s',a1) = -1 + 4 = 3. Target 1 + 0.9 * 3 = 3.7, error 0.2:
// alpha 0.5 spread over 2 tilings moves rows 1 and 4 of a0 by 0.25 * 0.2 = 0.05 each, Q(s,a0)
// by alpha * error = 0.1.
TEST(TileCodedAgent, AnUpdateSpreadsAlphaOverTheTilings)
{
  QLearningAgent agent(twoTilings(), 0);
  agent.table().at(1, 0) = 1.5;
  agent.table().at(4, 0) = 2.0;
  agent.table().at(5, 0) = 0.5;
  agent.table().at(1, 1) = -1.0;
  agent.table().at(5, 1) = 4.0;
  const std::vector<double> before = agent.table().values();
  ActiveRows s, next;
  agent.activeRows(CartPoleState(0.0, 0.0, 0.0, 0.25), s);
  agent.activeRows(CartPoleState(0.0, 0.0, 0.0, 0.75), next);
  ASSERT_EQ(1u, next.rows[0]);
  ASSERT_EQ(5u, next.rows[1]);

  const cartpole_qlearning::QUpdate u = agent.update(s, 0, 1.0, next, false, 0.5);
  EXPECT_DOUBLE_EQ(3.5, u.old_value);
  EXPECT_DOUBLE_EQ(3.7, u.target);
  EXPECT_DOUBLE_EQ(3.6, u.new_value);
  EXPECT_DOUBLE_EQ(3.6, agent.value(s, 0));
  EXPECT_DOUBLE_EQ(1.55, agent.table().at(1, 0));
  EXPECT_DOUBLE_EQ(2.05, agent.table().at(4, 0));
  for (std::size_t i = 0; i < before.size(); ++i)
  {
    if (i != 1 * 2 + 0 && i != 4 * 2 + 0)
    {
      EXPECT_EQ(before[i], agent.table().values()[i]) << "weight " << i << " is not active for (s, a0)";
    }
  }

  // A fall does not bootstrap: target = reward = 1, error 1 - 3.6.
  const cartpole_qlearning::QUpdate fall = agent.update(s, 0, 1.0, next, true, 0.5);
  EXPECT_DOUBLE_EQ(1.0, fall.target);
  EXPECT_DOUBLE_EQ(3.6 + 0.5 * (1.0 - 3.6), fall.new_value);
}

// activeTiles looks its carries up in a table built once; here each tiling's tile is worked out
// from the definition (the value's cell on a grid tilings times finer than a tile, plus the
// tiling's offset, divided by tilings), for random states inside and outside the bounds.
TEST(TileCoder, TheTilesAreThoseOfTheDefinitionForEveryTiling)
{
  std::vector<TileCoderParams> shapes(4);
  shapes[0].tilings = 8;  // config/robust.yaml's
  shapes[0].tiles = {{3, 3, 8, 12}};
  shapes[0].lower = {{-1.0, -1.0, -0.2094, -0.8727}};
  shapes[0].upper = {{1.0, 1.0, 0.2094, 0.8727}};
  shapes[1].tilings = 64;
  shapes[1].tiles = {{2, 1, 5, 7}};
  shapes[2].tilings = 3;
  shapes[2].tiles = {{1, 4, 1, 1}};
  shapes[3].tilings = 1;
  shapes[3].tiles = {{2, 2, 2, 2}};
  RandomStream rng(7, kEnvironmentStream);
  for (const TileCoderParams& p : shapes)
  {
    const TileCoder coder(p);
    const unsigned n = p.tilings;
    for (int draw = 0; draw < 2000; ++draw)
    {
      CartPoleState state;
      for (std::size_t d = 0; d < kStateDimensions; ++d)
      {
        const double span = p.upper[d] - p.lower[d];
        state[d] = rng.uniform(p.lower[d] - 0.2 * span, p.upper[d] + 0.2 * span);
      }
      const Tiles tiles = active(coder, state);
      for (unsigned i = 0; i < n; ++i)
      {
        std::size_t expected = i * coder.tilesPerTiling();
        std::size_t stride = 1;
        for (std::size_t d = kStateDimensions; d-- > 0;)
        {
          if (p.tiles[d] == 1)
            continue;
          const unsigned fine = uniformBin(state[d], p.lower[d], p.upper[d], p.tiles[d] * n);
          expected += stride * ((fine + coder.offset(i, d)) / n);
          stride *= p.tiles[d] + 1;
        }
        ASSERT_EQ(expected, tiles[i]) << "tilings " << n << ", tiling " << i << ", draw " << draw;
      }
    }
  }
}

namespace
{
// The two tilings above, and a second tile coding of four tiles of theta_dot over the same bounds.
FeatureParams withSecondTiles()
{
  FeatureParams p = twoTilings().featureParams();
  p.second_tiles = {{1, 1, 1, 4}};
  return p;
}
}  // namespace

TEST(SecondTileCoding, ItsRowsFollowTheFirstsAndEveryStateActivatesATileOfEachTiling)
{
  const FeatureParams params = withSecondTiles();
  const FeatureMap map(params, 2);
  const TileCoder first(params.tileCoder());
  const TileCoder second(params.secondTileCoder());
  EXPECT_EQ(6u, first.tileCount());    // 2 tilings of 3 tiles
  EXPECT_EQ(10u, second.tileCount());  // 2 tilings of 5 tiles
  EXPECT_EQ(16u, map.rowCount());
  EXPECT_EQ(4u, params.activeRowCount());
  for (const double theta_dot : {-0.9, -0.3, 0.1, 0.6})
  {
    const CartPoleState state(0.0, 0.0, 0.0, theta_dot);
    ActiveRows rows;
    map.activeRows(state, rows);
    ASSERT_EQ(4u, rows.count);
    const Tiles own_first = active(first, state);
    const Tiles own_second = active(second, state);
    EXPECT_EQ(own_first, (Tiles{rows.rows[0], rows.rows[1]}));
    EXPECT_EQ((Tiles{own_second[0] + 6, own_second[1] + 6}), (Tiles{rows.rows[2], rows.rows[3]}));
  }
}

TEST(SecondTileCoding, OptimismAndUpdatesSpreadOverBothCodings)
{
  AgentParams p = twoTilings();
  p.second_tiles = {{1, 1, 1, 4}};
  p.initial_value = 8.0;
  QLearningAgent agent(p, 0);
  ActiveRows s;
  agent.activeRows(CartPoleState(0.0, 0.0, 0.0, 0.25), s);
  EXPECT_DOUBLE_EQ(8.0, agent.value(s, 0));  // each of 4 rows holds a quarter
  agent.update(s, 0, 1.0, s, true, 0.5);     // terminal: target 1, Q moves halfway
  EXPECT_DOUBLE_EQ(4.5, agent.value(s, 0));
}

TEST(SecondTileCoding, ATableWithItRoundTripsThroughItsFileAndATableWithoutIsWrittenAsBefore)
{
  QTable table(withSecondTiles(), {-10.0, 10.0});
  for (std::size_t row = 0; row < table.stateCount(); ++row)
    table.at(row, row % 2) = 0.25 * static_cast<double>(row);
  const std::string text = formatQTable(table);
  EXPECT_NE(std::string::npos, text.find("second_tiles: [1, 1, 1, 4]"));
  const QTable read = parseQTable(text);
  EXPECT_EQ("", table.features().mismatch(read.features()));
  EXPECT_EQ(table.values(), read.values());

  QTable one_coding(twoTilings().featureParams(), {-10.0, 10.0});
  EXPECT_EQ(std::string::npos, formatQTable(one_coding).find("second_tiles"));
  EXPECT_NE("", one_coding.features().mismatch(table.features()));
}

TEST(SecondTileCoding, IsRefusedWithBinsAndWithMoreThanHalfTheTilings)
{
  AgentParams bins;
  bins.second_tiles = {{1, 1, 2, 2}};
  EXPECT_NE(std::string::npos, bins.validate().find("second_tiles is not allowed with features bins"))
      << bins.validate();
  AgentParams many = twoTilings();
  many.second_tiles = {{1, 1, 1, 4}};
  many.tilings = kMaxTilings / 2 + 1;
  EXPECT_NE(std::string::npos, many.validate().find("second_tiles with tilings")) << many.validate();
  many.tilings = kMaxTilings / 2;
  EXPECT_EQ("", many.validate());
}

namespace
{
// The two tilings above, the second coding, and an energy coding of two tiles of the energy and two
// of theta_dot * cos(theta).
FeatureParams withEnergyTiles()
{
  FeatureParams p = withSecondTiles();
  p.energy_tiles = {{1, 1, 2, 2}};
  return p;
}
}  // namespace

TEST(EnergyTileCoding, CodesThePolesEnergyRelativeToUprightsAndThePumpingPhase)
{
  const FeatureParams params = withEnergyTiles();
  // Upright at rest, and a swing through the bottom that just reaches the top: the same energy.
  EXPECT_DOUBLE_EQ(0.0, params.swingState(CartPoleState(0.3, -0.2, 0.0, 0.0))[2]);
  const double reaching = 2.0 * params.pole_frequency;  // (theta_dot / w)^2 / 2 = 2
  EXPECT_NEAR(0.0, params.swingState(CartPoleState(0.0, 0.0, M_PI, reaching))[2], 1e-12);
  EXPECT_NEAR(-2.0, params.swingState(CartPoleState(0.0, 0.0, -M_PI, 0.0))[2], 1e-12);
  // The cart's part as it is, theta_dot * cos(theta) the phase: its sign flips past horizontal.
  const CartPoleState below = params.swingState(CartPoleState(0.3, -0.2, 2.5, 1.0));
  EXPECT_EQ(0.3, below[0]);
  EXPECT_EQ(-0.2, below[1]);
  EXPECT_DOUBLE_EQ(std::cos(2.5), below[3]);
  EXPECT_GT(0.0, below[3]);
  EXPECT_LT(0.0, params.swingState(CartPoleState(0.0, 0.0, 0.5, 1.0))[3]);
  // A turn further on is the same pole.
  EXPECT_NEAR(below[2], params.swingState(CartPoleState(0.3, -0.2, 2.5 + 2.0 * M_PI, 1.0))[2], 1e-12);
  // Tiled over [-2, 2] and +-theta_dot's bound, x and x_dot over theirs.
  const TileCoderParams coder = params.energyTileCoder();
  EXPECT_EQ(-2.0, coder.lower[2]);
  EXPECT_EQ(2.0, coder.upper[2]);
  EXPECT_EQ(-1.0, coder.lower[3]);
  EXPECT_EQ(1.0, coder.upper[3]);
  EXPECT_EQ(params.discretiser.lower[0], coder.lower[0]);
  EXPECT_EQ(params.discretiser.upper[1], coder.upper[1]);
}

TEST(EnergyTileCoding, ItsRowsFollowTheOthersAndStatesOfOneEnergyAndPhaseShareThem)
{
  const FeatureParams params = withEnergyTiles();
  const FeatureMap map(params, 2);
  const TileCoder energy(params.energyTileCoder());
  EXPECT_EQ(18u, energy.tileCount());  // 2 tilings of 3 x 3 tiles
  EXPECT_EQ(6u + 10u + 18u, map.rowCount());
  EXPECT_EQ(6u, params.activeRowCount());
  const CartPoleState state(0.0, 0.0, 2.0, 0.9);
  ActiveRows rows;
  map.activeRows(state, rows);
  ASSERT_EQ(6u, rows.count);
  const Tiles own = active(energy, params.swingState(state));
  EXPECT_EQ((Tiles{own[0] + 16, own[1] + 16}), (Tiles{rows.rows[4], rows.rows[5]}));
  // The same energy and phase at the mirror angle, swinging the other way: the same energy rows.
  ActiveRows mirror;
  map.activeRows(CartPoleState(0.0, 0.0, -2.0, 0.9), mirror);
  EXPECT_EQ((Tiles{rows.rows[4], rows.rows[5]}), (Tiles{mirror.rows[4], mirror.rows[5]}));
  // Without it, the first two codings' rows are what they were.
  ActiveRows two;
  FeatureMap(withSecondTiles(), 2).activeRows(state, two);
  ASSERT_EQ(4u, two.count);
  for (unsigned i = 0; i < 4; ++i)
    EXPECT_EQ(two.rows[i], rows.rows[i]);
}

TEST(EnergyTileCoding, OptimismAndUpdatesSpreadOverAllThreeCodings)
{
  AgentParams p = twoTilings();
  p.second_tiles = {{1, 1, 1, 4}};
  p.energy_tiles = {{1, 1, 2, 2}};
  p.initial_value = 6.0;
  QLearningAgent agent(p, 0);
  ActiveRows s;
  agent.activeRows(CartPoleState(0.0, 0.0, 3.0, 0.25), s);
  ASSERT_EQ(6u, s.count);
  EXPECT_DOUBLE_EQ(6.0, agent.value(s, 0));  // each of 6 rows holds a sixth
  agent.update(s, 0, 1.0, s, true, 0.5);     // terminal: target 1, Q moves halfway
  EXPECT_DOUBLE_EQ(3.5, agent.value(s, 0));
}

TEST(EnergyTileCoding, ATableWithItRoundTripsThroughItsFileAndATableWithoutIsWrittenAsBefore)
{
  FeatureParams params = withEnergyTiles();
  params.pole_frequency = 3.5;
  QTable table(params, {-10.0, 10.0});
  for (std::size_t row = 0; row < table.stateCount(); ++row)
    table.at(row, row % 2) = 0.25 * static_cast<double>(row);
  const std::string text = formatQTable(table);
  EXPECT_NE(std::string::npos, text.find("energy_tiles: [1, 1, 2, 2]"));
  EXPECT_NE(std::string::npos, text.find("pole_frequency: 3.5"));
  const QTable read = parseQTable(text);
  EXPECT_EQ("", table.features().mismatch(read.features()));
  EXPECT_EQ(3.5, read.features().pole_frequency);
  EXPECT_EQ(table.values(), read.values());

  QTable two_codings(withSecondTiles(), {-10.0, 10.0});
  EXPECT_EQ(std::string::npos, formatQTable(two_codings).find("energy_tiles"));
  EXPECT_EQ(std::string::npos, formatQTable(two_codings).find("pole_frequency"));
  EXPECT_NE("", two_codings.features().mismatch(table.features()));
  FeatureParams other_frequency = params;
  other_frequency.pole_frequency = 4.0;
  EXPECT_NE(std::string::npos, params.mismatch(other_frequency).find("pole_frequency"))
      << params.mismatch(other_frequency);
}

TEST(EnergyTileCoding, IsRefusedWithBinsWithTooManyTilingsAndWithABadFrequency)
{
  AgentParams bins;
  bins.energy_tiles = {{1, 1, 2, 2}};
  EXPECT_NE(std::string::npos, bins.validate().find("energy_tiles is not allowed with features bins"))
      << bins.validate();
  AgentParams many = twoTilings();
  many.second_tiles = {{1, 1, 1, 4}};
  many.energy_tiles = {{1, 1, 2, 2}};
  many.tilings = kMaxTilings / 3 + 1;
  EXPECT_NE(std::string::npos, many.validate().find("tilings must be at most 21")) << many.validate();
  many.tilings = kMaxTilings / 3;
  EXPECT_EQ("", many.validate());
  many.pole_frequency = 0.0;
  EXPECT_NE(std::string::npos, many.validate().find("pole_frequency = 0 is not allowed")) << many.validate();
}

namespace
{
// Two tilings over theta and theta_dot, three symmetric actions, the mirror on.
AgentParams mirrored()
{
  AgentParams p = twoTilings();
  p.tiles = {{1, 1, 2, 2}};
  p.discretiser.lower[2] = -1.0;
  p.discretiser.upper[2] = 1.0;
  p.actions = {-10.0, 0.0, 10.0};
  p.mirror = true;
  return p;
}
}  // namespace

TEST(Mirror, AStateWithThetaBelowZeroIsSeenAsItsMirrorImageWithItsActionsReversed)
{
  const FeatureMap map(mirrored().featureParams(), 3);
  ActiveRows right;
  ActiveRows left;
  map.activeRows(CartPoleState(0.1, 0.2, 0.3, -0.4), right);
  map.activeRows(CartPoleState(-0.1, -0.2, -0.3, 0.4), left);
  EXPECT_FALSE(right.mirrored);
  EXPECT_TRUE(left.mirrored);
  ASSERT_EQ(right.count, left.count);
  for (unsigned i = 0; i < right.count; ++i)
    EXPECT_EQ(right.rows[i], left.rows[i]);
  EXPECT_EQ(0u, left.column(2, 3));
  EXPECT_EQ(1u, left.column(1, 3));
  EXPECT_EQ(2u, right.column(2, 3));
  // A turn further on is the same pole, the mirror decided on the wrapped angle.
  ActiveRows turned;
  map.activeRows(CartPoleState(-0.1, -0.2, -0.3 + 2.0 * M_PI, 0.4), turned);
  EXPECT_TRUE(turned.mirrored);
  // A row reused for an unmirrored state forgets it was mirrored.
  map.activeRows(CartPoleState(0.1, 0.2, 0.3, -0.4), left);
  EXPECT_FALSE(left.mirrored);
}

TEST(Mirror, WhatIsLearntOnOneSideIsTheMirroredActionsOnTheOther)
{
  QLearningAgent agent(mirrored(), 0);
  ActiveRows right;
  ActiveRows left;
  agent.activeRows(CartPoleState(0.0, 0.0, 0.3, -0.4), right);
  agent.activeRows(CartPoleState(0.0, 0.0, -0.3, 0.4), left);
  agent.update(right, 2, 1.0, right, true, 0.5);  // pushing +x from the right: target 1, halfway
  EXPECT_DOUBLE_EQ(0.5, agent.value(right, 2));
  EXPECT_DOUBLE_EQ(0.5, agent.value(left, 0));  // pushing -x from the mirror image
  EXPECT_DOUBLE_EQ(0.0, agent.value(left, 2));
  EXPECT_EQ(2u, agent.greedyAction(right));
  EXPECT_EQ(0u, agent.greedyAction(left));
  // Through the traces too.
  AgentParams traced = mirrored();
  traced.lambda = 0.9;
  QLearningAgent with_traces(traced, 0);
  EligibilityTraces traces;
  with_traces.update(left, 0, 1.0, left, true, 0.5, &traces);
  EXPECT_DOUBLE_EQ(0.5, with_traces.value(right, 2));
  EXPECT_EQ(0u, with_traces.greedyAction(left));
}

TEST(Mirror, NeedsSymmetricActionsAndNoPreviousAction)
{
  AgentParams p = mirrored();
  EXPECT_EQ("", p.validate());
  p.actions = {-10.0, 0.0, 4.0};
  EXPECT_NE(std::string::npos, p.validate().find("must be symmetric")) << p.validate();
  p.actions = {-10.0, 10.0};
  EXPECT_EQ("", p.validate());
  p.previous_action = true;
  EXPECT_NE(std::string::npos, p.validate().find("mirror is not allowed with previous_action")) << p.validate();
}
