#include "cartpole_qlearning/learning/tile_coder.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
std::string TileCoderParams::validate() const
{
  std::ostringstream out;
  if (tilings < 1 || tilings > kMaxTilings)
  {
    out << "tilings = " << tilings << " is not allowed (must be in [1, " << kMaxTilings << "])";
    return out.str();
  }
  const std::string error = uniformGridError("tiles", tiles, lower, upper);
  if (!error.empty())
    return error;
  std::uint64_t per_tiling = 1;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
    per_tiling *= tiles[d] > 1 ? tiles[d] + 1 : 1;  // at most 1001^4: no overflow
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
  return tilings == other.tilings && sameUniformGrid(tiles, lower, upper, other.tiles, other.lower, other.upper);
}

TileCoder::TileCoder(const TileCoderParams& params) : params_(params)
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    span_[d] = params_.tiles[d] > 1 ? params_.tiles[d] + 1 : 1;
    tiles_per_tiling_ *= span_[d];
    if (span_[d] > 1)
      used_[used_count_++] = d;
  }
  for (unsigned k = 0; k < used_count_; ++k)
  {
    stride_[k] = 1;
    for (std::size_t d = used_[k] + 1; d < kStateDimensions; ++d)
      stride_[k] *= span_[d];
    const unsigned odd = 2 * k + 1;  // Sutton and Barto's displacement vector (1, 3, 5, 7, ...)
    for (unsigned i = 0; i < params_.tilings; ++i)
      offsets_[i][k] = (i * odd) % params_.tilings;
  }
  const unsigned n = params_.tilings;
  tiling_starts_.resize(n);
  for (unsigned i = 0; i < n; ++i)
    tiling_starts_[i] = static_cast<std::uint32_t>(i * tiles_per_tiling_);
  carries_.assign(static_cast<std::size_t>(used_count_) * n * n, 0);
  for (unsigned k = 0; k < used_count_; ++k)
    for (unsigned part = 0; part < n; ++part)
      for (unsigned i = 0; i < n; ++i)
        carries_[(k * n + part) * n + i] = part + offsets_[i][k] >= n ? static_cast<std::uint32_t>(stride_[k]) : 0;
}

unsigned TileCoder::offset(unsigned tiling, std::size_t dimension) const
{
  for (unsigned k = 0; k < used_count_; ++k)
  {
    if (used_[k] == dimension)
      return offsets_[tiling][k];
  }
  return 0;
}

void TileCoder::activeTiles(const CartPoleState& state, std::uint32_t* tiles) const
{
  const unsigned n = params_.tilings;
  // Where the value falls on a grid n times finer than a tile: tiling i's tile is
  // (fine + offset_i) / n, so one division per dimension serves every tiling and a tile edge is
  // exactly a fine-cell edge. With fine = n * whole + part that is whole, plus one when
  // part + offset_i reaches n: the carry, looked up per tiling (carries_).
  std::uint32_t base = 0;
  for (unsigned k = 0; k < used_count_; ++k)
  {
    const std::size_t d = used_[k];
    const unsigned fine = uniformBin(state[d], params_.lower[d], params_.upper[d], params_.tiles[d] * n);
    const unsigned whole = fine / n;
    base += static_cast<std::uint32_t>(stride_[k] * whole);
    const std::uint32_t* carry = &carries_[(k * n + (fine - whole * n)) * n];
    if (k == 0)
      for (unsigned i = 0; i < n; ++i)
        tiles[i] = tiling_starts_[i] + carry[i];
    else
      for (unsigned i = 0; i < n; ++i)
        tiles[i] += carry[i];
  }
  if (used_count_ == 0)
    for (unsigned i = 0; i < n; ++i)
      tiles[i] = tiling_starts_[i];
  for (unsigned i = 0; i < n; ++i)
    tiles[i] += base;
}

}  // namespace cartpole_qlearning
