#include "cartpole_qlearning/tile_coder.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
const char* const kDimensionNames[kStateDimensions] = {"x", "x_dot", "theta", "theta_dot"};
}  // namespace

std::string TileCoderParams::validate() const
{
  std::ostringstream out;
  if (tilings < 1 || tilings > kMaxTilings)
  {
    out << "tilings = " << tilings << " is not allowed (must be in [1, " << kMaxTilings << "])";
    return out.str();
  }
  std::uint64_t per_tiling = 1;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (tiles[d] < 1 || tiles[d] > kMaxBinsPerDimension)
    {
      out << "tiles[" << d << "] (" << kDimensionNames[d] << ") = " << tiles[d] << " is not allowed (must be in [1, "
          << kMaxBinsPerDimension << "])";
      return out.str();
    }
    if (tiles[d] > 1 && !(std::isfinite(lower[d]) && std::isfinite(upper[d]) && lower[d] < upper[d]))
    {
      out << "lower_bounds[" << d << "], upper_bounds[" << d << "] (" << kDimensionNames[d] << ") = " << lower[d]
          << ", " << upper[d] << " are not allowed (must be finite with lower < upper)";
      return out.str();
    }
    per_tiling *= tiles[d] > 1 ? tiles[d] + 1 : 1;  // at most 1001^4: no overflow
  }
  const std::uint64_t total = per_tiling * tilings;
  if (total > kMaxStates)
  {
    out << "tiles give " << total << " tiles (" << tilings << " tilings of " << per_tiling
        << ", each used dimension one tile more than its tiles), more than the " << kMaxStates << " allowed";
    return out.str();
  }
  return "";
}

bool TileCoderParams::operator==(const TileCoderParams& other) const
{
  if (tilings != other.tilings || tiles != other.tiles)
    return false;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (tiles[d] > 1 && (lower[d] != other.lower[d] || upper[d] != other.upper[d]))
      return false;
  }
  return true;
}

TileCoder::TileCoder(const TileCoderParams& params) : params_(params)
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
  unsigned odd = 1;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    const bool used = params_.tiles[d] > 1;
    span_[d] = used ? params_.tiles[d] + 1 : 1;
    tiles_per_tiling_ *= span_[d];
    for (unsigned i = 0; i < params_.tilings; ++i)
      offsets_[i][d] = used ? (i * odd) % params_.tilings : 0;
    if (used)
      odd += 2;
  }
}

void TileCoder::activeTiles(const CartPoleState& state, std::uint32_t* tiles) const
{
  const unsigned n = params_.tilings;
  // Where the value falls on a grid n times finer than one tiling: a tile is n consecutive fine
  // cells, and tiling i's tiles start n - offset cells earlier, so one division per dimension
  // serves every tiling and a tile edge is exactly a fine-cell edge.
  std::array<unsigned, kStateDimensions> fine{};
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (span_[d] > 1)
      fine[d] = uniformBin(state[d], params_.lower[d], params_.upper[d], params_.tiles[d] * n);
  }
  for (unsigned i = 0; i < n; ++i)
  {
    std::size_t tile = 0;
    for (std::size_t d = 0; d < kStateDimensions; ++d)
      tile = tile * span_[d] + (span_[d] > 1 ? (fine[d] + offsets_[i][d]) / n : 0);
    tiles[i] = static_cast<std::uint32_t>(i * tiles_per_tiling_ + tile);
  }
}

}  // namespace cartpole_qlearning
