#include "cartpole_qlearning/learning/features.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
FeatureKind featureKindFromString(const std::string& name)
{
  if (name == "bins")
    return FeatureKind::Bins;
  if (name == "tiles")
    return FeatureKind::Tiles;
  throw std::invalid_argument("allowed: bins, tiles");
}

std::string toString(FeatureKind kind)
{
  return kind == FeatureKind::Tiles ? "tiles" : "bins";
}

TileCoderParams FeatureParams::tileCoder() const
{
  TileCoderParams coder;
  coder.tilings = tilings;
  coder.tiles = tiles;
  coder.lower = discretiser.lower;
  coder.upper = discretiser.upper;
  return coder;
}

TileCoderParams FeatureParams::secondTileCoder() const
{
  TileCoderParams coder = tileCoder();
  coder.tiles = second_tiles;
  return coder;
}

TileCoderParams FeatureParams::energyTileCoder() const
{
  TileCoderParams coder = tileCoder();
  coder.tiles = energy_tiles;
  coder.lower[2] = -2.0;
  coder.upper[2] = 2.0;
  coder.lower[3] = -discretiser.upper[3];
  coder.upper[3] = discretiser.upper[3];
  return coder;
}

std::string FeatureParams::validate() const
{
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    std::ostringstream out;
    if (!(warp[d] >= 1.0 && warp[d] <= 10.0))
      out << "warp[" << d << "] = " << warp[d] << " is not allowed (must be in [1, 10])";
    else if (warp[d] != 1.0 && !(discretiser.upper[d] > 0.0 && discretiser.lower[d] == -discretiser.upper[d]))
      out << "warp[" << d << "] = " << warp[d] << " is not allowed with bounds [" << discretiser.lower[d] << ", "
          << discretiser.upper[d] << "] (a warped dimension's bounds must be symmetric about 0)";
    if (!out.str().empty())
      return out.str();
  }
  if (mirror && previous_action)
    return "mirror is not allowed with previous_action (the previous action's rows would need mirroring too)";
  if (kind != FeatureKind::Tiles)
  {
    if (hasSecondTiles())
      return "second_tiles is not allowed with features bins (it is a second tile coding)";
    if (hasEnergyTiles())
      return "energy_tiles is not allowed with features bins (it is a tile coding)";
    return discretiser.validate();
  }
  std::string error = tileCoder().validate();
  if (!error.empty() || (!hasSecondTiles() && !hasEnergyTiles()))
    return error;
  const unsigned active = activeRowCount();
  if (active > kMaxTilings)
    return std::string(hasSecondTiles() ? "second_tiles" : "energy_tiles") +
           " with tilings = " + std::to_string(tilings) + " is not allowed (a state then activates " +
           std::to_string(active) + " rows; tilings must be at most " + std::to_string(kMaxTilings / codings()) + ")";
  if (hasSecondTiles())
  {
    error = secondTileCoder().validate();
    if (!error.empty())
      return "second_tiles: " + error;
  }
  if (!hasEnergyTiles())
    return "";
  if (!(std::isfinite(pole_frequency) && pole_frequency > 0.0))
  {
    std::ostringstream out;
    out << "pole_frequency = " << pole_frequency << " is not allowed (must be finite and > 0)";
    return out.str();
  }
  if (!(discretiser.upper[3] > 0.0))
  {
    std::ostringstream out;
    out << "energy_tiles is not allowed with upper_bounds[3] = " << discretiser.upper[3]
        << " (theta_dot * cos(theta) is tiled over +-upper_bounds[3]: it must be > 0)";
    return out.str();
  }
  error = energyTileCoder().validate();
  return error.empty() ? "" : "energy_tiles: " + error;
}

std::size_t FeatureParams::stateRowCount() const
{
  if (kind != FeatureKind::Tiles)
    return Discretiser(discretiser).stateCount();
  std::size_t rows = TileCoder(tileCoder()).tileCount();
  if (hasSecondTiles())
    rows += TileCoder(secondTileCoder()).tileCount();
  if (hasEnergyTiles())
    rows += TileCoder(energyTileCoder()).tileCount();
  return rows;
}

std::size_t FeatureParams::rowCount(std::size_t actions) const
{
  return stateRowCount() * blocks(actions);
}

namespace
{
template <typename Container>
std::string fullPrecisionList(const Container& values)
{
  std::ostringstream out;
  out.precision(17);
  out << "[";
  bool first = true;
  for (const auto& v : values)
  {
    out << (first ? "" : ", ") << v;
    first = false;
  }
  out << "]";
  return out.str();
}

std::string boundsText(const DiscretiserParams& d)
{
  return "lower " + fullPrecisionList(d.lower) + " upper " + fullPrecisionList(d.upper);
}
}  // namespace

std::string FeatureParams::mismatch(const FeatureParams& other) const
{
  if (kind != other.kind)
    return "features " + toString(other.kind) + " differ from " + toString(kind);
  if (previous_action != other.previous_action)
    return std::string("previous_action ") + (other.previous_action ? "true" : "false") + " differs from " +
           (previous_action ? "true" : "false");
  if (kind == FeatureKind::Bins)
  {
    if (discretiser.bins != other.discretiser.bins)
      return "bins " + fullPrecisionList(other.discretiser.bins) + " differ from " +
             fullPrecisionList(discretiser.bins);
    if (!(discretiser == other.discretiser))
      return "bin bounds " + boundsText(other.discretiser) + " differ from " + boundsText(discretiser);
    return "";
  }
  if (tilings != other.tilings)
    return "tilings " + std::to_string(other.tilings) + " differ from " + std::to_string(tilings);
  if (tiles != other.tiles)
    return "tiles " + fullPrecisionList(other.tiles) + " differ from " + fullPrecisionList(tiles);
  if (second_tiles != other.second_tiles)
    return "second_tiles " + fullPrecisionList(other.second_tiles) + " differ from " + fullPrecisionList(second_tiles);
  if (energy_tiles != other.energy_tiles)
    return "energy_tiles " + fullPrecisionList(other.energy_tiles) + " differ from " + fullPrecisionList(energy_tiles);
  if (hasEnergyTiles() && pole_frequency != other.pole_frequency)
    return "pole_frequency " + fullPrecisionList(std::array<double, 1>{{other.pole_frequency}}) + " differs from " +
           fullPrecisionList(std::array<double, 1>{{pole_frequency}});
  if (!(tileCoder() == other.tileCoder()) || (hasSecondTiles() && !(secondTileCoder() == other.secondTileCoder())) ||
      (hasEnergyTiles() && !(energyTileCoder() == other.energyTileCoder())))
    return "tile bounds " + boundsText(other.discretiser) + " differ from " + boundsText(discretiser);
  return "";
}

namespace
{
const FeatureParams& checked(const FeatureParams& params)
{
  const std::string error = params.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
  return params;
}
}  // namespace

FeatureMap::FeatureMap(const FeatureParams& params, std::size_t actions)
  : params_(checked(params)),
    discretiser_(params.kind == FeatureKind::Bins ? params.discretiser : DiscretiserParams()),
    state_rows_(discretiser_.stateCount()),
    warped_(params.warped())
{
  if (params_.kind == FeatureKind::Tiles)
  {
    tile_coder_.emplace(params_.tileCoder());
    state_rows_ = tile_coder_->tileCount();
    if (params_.hasSecondTiles())
    {
      second_coder_.emplace(params_.secondTileCoder());
      state_rows_ += second_coder_->tileCount();
    }
    if (params_.hasEnergyTiles())
    {
      energy_coder_.emplace(params_.energyTileCoder());
      energy_first_row_ = state_rows_;
      state_rows_ += energy_coder_->tileCount();
    }
  }
  row_count_ = state_rows_ * params_.blocks(actions);
}

}  // namespace cartpole_qlearning
