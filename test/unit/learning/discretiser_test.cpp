#include "cartpole_qlearning/learning/discretiser.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

using cartpole_qlearning::CartPoleState;
using cartpole_qlearning::Discretiser;
using cartpole_qlearning::DiscretiserParams;

namespace
{
// x: 4 bins on [-1, 1] (edges -1, -0.5, 0, 0.5, 1); x_dot ignored; theta: 3 bins on [-0.3, 0.3];
// theta_dot: 2 bins on [-2, 2].
DiscretiserParams exampleParams()
{
  DiscretiserParams p;
  p.bins = {{4, 1, 3, 2}};
  p.lower = {{-1.0, -5.0, -0.3, -2.0}};
  p.upper = {{1.0, 5.0, 0.3, 2.0}};
  return p;
}
}  // namespace

TEST(Discretiser, ValuesOnAnEdgeGoToTheBinThatStartsThere)
{
  const Discretiser d(exampleParams());
  EXPECT_EQ(0u, d.bin(0, -1.0));
  EXPECT_EQ(0u, d.bin(0, std::nextafter(-0.5, -1.0)));
  EXPECT_EQ(1u, d.bin(0, -0.5));
  EXPECT_EQ(1u, d.bin(0, std::nextafter(0.0, -1.0)));
  EXPECT_EQ(2u, d.bin(0, 0.0));
  EXPECT_EQ(3u, d.bin(0, 0.5));
  EXPECT_EQ(3u, d.bin(0, std::nextafter(1.0, 0.0)));
}

TEST(Discretiser, EdgesThatAreNotExactInBinaryStillSplitConsistently)
{
  // Three bins on [-0.3, 0.3]: the inner edges -0.1 and 0.1 are not representable exactly.
  const Discretiser d(exampleParams());
  const double width = 0.6 / 3;
  const double edge = -0.3 + width;
  EXPECT_EQ(0u, d.bin(2, std::nextafter(edge, -1.0)));
  EXPECT_EQ(1u, d.bin(2, edge));
  EXPECT_EQ(1u, d.bin(2, 0.0));
  EXPECT_EQ(2u, d.bin(2, -0.3 + 2 * width));
}

TEST(Discretiser, ValuesOutsideTheBoundsAreClippedToTheEndBins)
{
  const Discretiser d(exampleParams());
  EXPECT_EQ(0u, d.bin(0, -1e9));
  EXPECT_EQ(3u, d.bin(0, 1.0));
  EXPECT_EQ(3u, d.bin(0, 1e9));
  EXPECT_EQ(0u, d.bin(0, -std::numeric_limits<double>::infinity()));
  EXPECT_EQ(3u, d.bin(0, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(0u, d.bin(0, std::nan("")));
}

TEST(Discretiser, AOneBinDimensionIsIgnored)
{
  const Discretiser d(exampleParams());
  EXPECT_EQ(0u, d.bin(1, -100.0));
  EXPECT_EQ(0u, d.bin(1, 100.0));
  EXPECT_EQ(d.index(CartPoleState(0.2, -100.0, 0.0, 1.0)), d.index(CartPoleState(0.2, 100.0, 0.0, 1.0)));
}

TEST(Discretiser, IndexCombinesBinsInMixedRadixFirstDimensionMostSignificant)
{
  const Discretiser d(exampleParams());
  EXPECT_EQ(4u * 1u * 3u * 2u, d.stateCount());
  // bins (x=2, x_dot=0, theta=1, theta_dot=1): ((2 * 1 + 0) * 3 + 1) * 2 + 1 = 15
  EXPECT_EQ(15u, d.index(CartPoleState(0.1, 0.0, 0.0, 1.0)));
  EXPECT_EQ(0u, d.index(CartPoleState(-5, 0, -5, -5)));
  EXPECT_EQ(d.stateCount() - 1, d.index(CartPoleState(5, 0, 5, 5)));
}

TEST(Discretiser, DefaultIsTheTutorialsSixByTwelve)
{
  const Discretiser d;
  EXPECT_EQ(72u, d.stateCount());
}

TEST(Discretiser, BadParametersAreRefusedWithTheirName)
{
  DiscretiserParams p = exampleParams();
  p.bins[2] = 0;
  EXPECT_NE(std::string::npos, p.validate().find("bins[2] (theta) = 0")) << p.validate();
  EXPECT_THROW(Discretiser d(p), std::invalid_argument);
  p = exampleParams();
  p.lower[3] = 2.0;
  EXPECT_NE(std::string::npos, p.validate().find("theta_dot")) << p.validate();
  // Bounds of an ignored dimension do not matter.
  p = exampleParams();
  p.lower[1] = p.upper[1] = std::nan("");
  EXPECT_EQ("", p.validate());
}

TEST(Discretiser, ItsWidthsWorkedOutOnceBinAsUniformBinsOwnDivision)
{
  // The discretiser divides each dimension's range by its bins once, not on every value: the same
  // quotient, so the same bins, checked on every edge, its neighbours either side and values
  // between, for grids whose edges are exact in binary and grids whose edges are not.
  const std::array<DiscretiserParams, 3> grids = [] {
    std::array<DiscretiserParams, 3> g;
    g[0] = exampleParams();
    g[1].bins = {{3, 3, 8, 12}};
    g[1].lower = {{-1.0, -1.0, -0.20943951023931953, -0.8726646259971648}};
    g[1].upper = {{1.0, 1.0, 0.20943951023931953, 0.8726646259971648}};
    g[2].bins = {{7, 99, 13, 1000}};
    g[2].lower = {{-2.4, -3.1, -0.3, -1e-3}};
    g[2].upper = {{2.3, 3.7, 0.1, 7e-3}};
    return g;
  }();
  std::uint64_t checked = 0;
  for (const DiscretiserParams& p : grids)
  {
    const Discretiser d(p);
    for (std::size_t dim = 0; dim < 4; ++dim)
    {
      const unsigned n = p.bins[dim];
      if (n == 1)
        continue;
      const double width = (p.upper[dim] - p.lower[dim]) / n;
      for (unsigned i = 0; i <= n; ++i)
      {
        const double edge = p.lower[dim] + i * width;
        for (const double v : {edge, std::nextafter(edge, -1e9), std::nextafter(edge, 1e9),
                               std::nextafter(std::nextafter(edge, -1e9), -1e9), edge + 0.5 * width,
                               edge - 0.25 * width, edge + 1e-12, edge - 1e-12})
        {
          EXPECT_EQ(d.bin(dim, v), cartpole_qlearning::uniformBin(v, p.lower[dim], p.upper[dim], n))
              << "dimension " << dim << " value " << v;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 9000u);
}
