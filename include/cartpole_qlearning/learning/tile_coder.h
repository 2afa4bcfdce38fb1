// Tile coding of the continuous cart-pole state (Sutton and Barto, Reinforcement Learning, 2nd
// ed., section 9.5.4): several overlapping grids (tilings) over the same bounds, each displaced
// by a different fraction of a tile, so that a state activates one tile in every tiling and
// nearby states share most of their tiles. A value is generalised over its neighbourhood while
// each tiling stays as cheap to index as one discretisation.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/discretiser.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The most tilings a config or a file may ask for (also the capacity of ActiveRows).
constexpr unsigned kMaxTilings = 64;

struct TileCoderParams
{
  unsigned tilings = 8;
  // Tiles per dimension (x, x_dot, theta, theta_dot) across the bounds; 1 ignores the dimension.
  std::array<unsigned, kStateDimensions> tiles{{1, 1, 6, 12}};
  // Values below lower / at or above upper are clipped into the tile at that edge.
  std::array<double, kStateDimensions> lower{DiscretiserParams().lower};
  std::array<double, kStateDimensions> upper{DiscretiserParams().upper};

  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
  // Equal when they map every state to the same tiles (bounds of ignored dimensions do not count).
  bool operator==(const TileCoderParams& other) const;
};

class TileCoder
{
public:
  // Throws std::invalid_argument with validate()'s message.
  explicit TileCoder(const TileCoderParams& params = TileCoderParams());

  const TileCoderParams& params() const
  {
    return params_;
  }
  unsigned tilings() const
  {
    return params_.tilings;
  }
  std::size_t tilesPerTiling() const
  {
    return tiles_per_tiling_;
  }
  // All tilings' tiles: the number of weight rows.
  std::size_t tileCount() const
  {
    return tiles_per_tiling_ * params_.tilings;
  }
  // Tiling i is displaced by offset(i, d) / tilings of a tile width along dimension d (towards
  // lower values): i times the odd number of d among the used dimensions (1, 3, 5, 7), modulo
  // tilings.
  unsigned offset(unsigned tiling, std::size_t dimension) const;

  // Writes the active tile of every tiling to tiles[0 .. tilings): tiling i's tile numbered
  // i * tilesPerTiling() + its tiles combined in mixed radix, first dimension most significant.
  // No allocation.
  void activeTiles(const CartPoleState& state, std::uint32_t* tiles) const;

private:
  TileCoderParams params_;
  std::array<unsigned, kStateDimensions> span_{};
  std::size_t tiles_per_tiling_ = 1;
  // The used dimensions (tiles > 1) in order, the stride of each in a tiling's mixed radix, and
  // each tiling's offset along each, so that the per-step loops skip the ignored dimensions.
  unsigned used_count_ = 0;
  std::array<std::size_t, kStateDimensions> used_{};
  std::array<std::size_t, kStateDimensions> stride_{};
  std::array<std::array<unsigned, kStateDimensions>, kMaxTilings> offsets_{};
  // What activeTiles adds per tiling, looked up rather than computed: each tiling's first tile
  // number, and for used dimension k and a value's place `part` within its tile (in tilings-ths),
  // carries_[(k * tilings + part) * tilings + i] is the stride of k when tiling i's displacement
  // carries that value into the next tile, else 0. Every step of training and of the suite codes
  // a state (8 tilings x 4 dimensions by default): two loops of additions over the tilings.
  std::vector<std::uint32_t> tiling_starts_;
  std::vector<std::uint32_t> carries_;
};

}  // namespace cartpole_qlearning
