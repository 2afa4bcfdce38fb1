// What the learner sees of a state: the rows of its weight table that the state activates.
// Bins activate one row (a discretised state); tiles activate one row per tiling. Q(s, a) is
// the sum of the active rows' weights for a, so both share one table, one learner and one file.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/discretiser.h"
#include "cartpole_qlearning/learning/tile_coder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
enum class FeatureKind
{
  Bins,  // uniform bins, one row per state (the tutorial's)
  Tiles  // tile coding, one row per tile of every tiling
};

// Parses "bins" or "tiles"; throws std::invalid_argument otherwise.
FeatureKind featureKindFromString(const std::string& name);
std::string toString(FeatureKind kind);

struct FeatureParams
{
  FeatureKind kind = FeatureKind::Bins;
  // Bins per dimension and the bounds; the bounds serve the tiles too.
  DiscretiserParams discretiser;
  unsigned tilings = 8;
  std::array<unsigned, kStateDimensions> tiles{{1, 1, 6, 12}};
  // The learner also sees the action it took last: what a robot that answers a step late is
  // still carrying out, which the state alone does not show. The rows repeat once for "none"
  // (an episode's first state) and once per action.
  bool previous_action = false;
  // Per dimension, a resolution that is finer near 0 (upright, at rest) than towards the bounds:
  // a value v within bounds [-b, b] is binned or tiled at b * sign(v) * (|v| / b)^(1 / warp), so
  // that the tiles next to 0 are narrower (warp 2, 10 tiles: b / 25 instead of b / 5) and the
  // outer ones wider (twice, for warp 2). 1: uniform (the
  // default); a warped dimension needs bounds symmetric about 0. Carried by the configuration a
  // table was trained with (its trained_with), not by the table's file.
  std::array<double, kStateDimensions> warp{{1.0, 1.0, 1.0, 1.0}};
  // The cart-pole's mirror symmetry: a state with theta < 0 (wrapped) is seen as its mirror image
  // (x, x_dot, theta, theta_dot all negated) and its actions' columns in reverse order (the learner's
  // actions must then be symmetric, actions[i] = -actions[n - 1 - i]), so that what is learnt on one
  // side of upright holds on the other: half the states, each visited twice as often. Carried, like
  // warp, by the configuration a table was trained with. Not with previous_action.
  bool mirror = false;
  // A second tile coding beside the first, summed into the same Q: as many tilings again over the
  // same (warped) bounds, with these tiles per dimension (1 ignores a dimension). A group over theta
  // and theta_dot alone, finer than the first, resolves the pole near upright without multiplying
  // its tiles by the cart's; the first then needs only as fine a grid as the cart's part of the
  // task. All 0 (the default): none. Tiles only.
  std::array<unsigned, kStateDimensions> second_tiles{{0, 0, 0, 0}};
  // A third tile coding, as many tilings again, over what a swing is made of rather than where the
  // pole is: (x, x_dot, the pole's energy, theta_dot * cos(theta)) with these tiles per dimension
  // (1 ignores one). The energy is relative to upright's, per m g l: cos(theta) - 1 + (theta_dot /
  // pole_frequency)^2 / 2, 0 for a swing that just reaches the top, -2 hanging at rest, tiled over
  // [-2, 2]; theta_dot * cos(theta) is positive where a push towards -x adds energy, tiled over
  // +-theta_dot's upper bound; x and x_dot over their bounds, none warped. What pumps the pole is
  // then learnt once for every angle of the swing. All 0 (the default): none. Tiles only.
  std::array<unsigned, kStateDimensions> energy_tiles{{0, 0, 0, 0}};
  // [rad/s] sqrt(m g l / I) of the pole about its hinge (l: the hinge to the centre of mass, I the
  // moment of inertia): a uniform pole of half-length 0.5 m under 9.81 m/s^2, sqrt(3 g / (4 l)).
  double pole_frequency = 3.8340579025361627;

  bool hasSecondTiles() const
  {
    return second_tiles != std::array<unsigned, kStateDimensions>{{0, 0, 0, 0}};
  }
  bool hasEnergyTiles() const
  {
    return energy_tiles != std::array<unsigned, kStateDimensions>{{0, 0, 0, 0}};
  }
  TileCoderParams secondTileCoder() const;
  TileCoderParams energyTileCoder() const;
  // The tile codings in use (1 for bins).
  unsigned codings() const
  {
    return kind == FeatureKind::Tiles ? 1 + (hasSecondTiles() ? 1 : 0) + (hasEnergyTiles() ? 1 : 0) : 1;
  }
  // The rows a state activates: 1 for bins, a row per tiling of each tile coding for tiles.
  unsigned activeRowCount() const
  {
    return kind == FeatureKind::Tiles ? tilings * codings() : 1;
  }
  // What energy_tiles codes of a state (theta wrapped or not): x, x_dot, the energy, theta_dot * cos(theta).
  CartPoleState swingState(const CartPoleState& state) const
  {
    const double cos_theta = std::cos(state[2]);
    const double speed = state[3] / pole_frequency;
    return CartPoleState(state[0], state[1], cos_theta - 1.0 + 0.5 * speed * speed, state[3] * cos_theta);
  }

  bool warped() const
  {
    return warp != std::array<double, kStateDimensions>{{1.0, 1.0, 1.0, 1.0}};
  }
  TileCoderParams tileCoder() const;
  // Empty when the kind in use is valid, else validate()'s message of its parameters.
  std::string validate() const;
  // Weight rows: states for bins, tiles of every tiling for tiles, times the previous action's
  // blocks. Valid params only.
  std::size_t rowCount(std::size_t actions) const;
  // The rows of one block: what the state alone activates.
  std::size_t stateRowCount() const;
  // 1, or (previous_action) one block for "none" and one per action.
  std::size_t blocks(std::size_t actions) const
  {
    return previous_action ? actions + 1 : 1;
  }
  // Empty when both map states to the same rows, else what differs ("tilings 4 differ from 8"),
  // the other's value first. Only the parameters of the kind in use count.
  std::string mismatch(const FeatureParams& other) const;
};

// The rows a state activates: rows[0 .. count). Fixed capacity, so that finding them allocates
// nothing.
struct ActiveRows
{
  std::array<std::uint32_t, kMaxTilings> rows{};
  unsigned count = 0;
  // FeatureParams::mirror: the state was seen as its mirror image, so action a's values are in
  // column actions - 1 - a.
  bool mirrored = false;

  // The table's column of an action of this state's (and the action of a column: its own inverse).
  std::size_t column(std::size_t action, std::size_t actions) const
  {
    return mirrored ? actions - 1 - action : action;
  }

  // One row: a discretised state.
  static ActiveRows single(std::size_t row)
  {
    ActiveRows active;
    active.rows[0] = static_cast<std::uint32_t>(row);
    active.count = 1;
    return active;
  }
};

class FeatureMap
{
public:
  // actions: how many actions the table has (the previous action's blocks). Throws
  // std::invalid_argument with validate()'s message.
  explicit FeatureMap(const FeatureParams& params = FeatureParams(), std::size_t actions = 2);

  const FeatureParams& params() const
  {
    return params_;
  }
  std::size_t rowCount() const
  {
    return row_count_;
  }
  // The discretiser of the bins (the default one, unused, for tiles).
  const Discretiser& discretiser() const
  {
    return discretiser_;
  }

  // previous: 0 for none (an episode's first state), 1 + the index of the action taken last;
  // ignored unless params().previous_action.
  // theta is seen on the circle, wrapped into [-pi, pi] (the pole turns whole turns in the Suite's
  // tasks): a pole a turn further on is the same pole. Angles already in [-pi, pi] are seen as they
  // are, so that CartPole-v1's tables stay as they were.
  void activeRows(const CartPoleState& state, ActiveRows& active, std::size_t previous = 0) const
  {
    active.mirrored = false;
    if (std::fabs(state[2]) > M_PI || warped_ || energy_coder_ || params_.mirror)
    {
      CartPoleState seen = state;
      if (std::fabs(state[2]) > M_PI)
        seen[2] = std::remainder(state[2], 2.0 * M_PI);
      if (params_.mirror && seen[2] < 0.0)
      {
        for (std::size_t d = 0; d < kStateDimensions; ++d)
          seen[d] = -seen[d];
        active.mirrored = true;
      }
      const CartPoleState swing = energy_coder_ ? params_.swingState(seen) : seen;
      if (warped_)
        warp(seen);
      codedRows(seen, active, previous, energy_coder_ ? &swing : nullptr);
      return;
    }
    codedRows(state, active, previous, nullptr);
  }

private:
  // FeatureParams::warp applied to the state's values.
  void warp(CartPoleState& state) const
  {
    for (std::size_t d = 0; d < kStateDimensions; ++d)
    {
      if (params_.warp[d] == 1.0)
        continue;
      const double bound = params_.discretiser.upper[d];
      const double ratio = std::min(std::fabs(state[d]) / bound, 1.0);
      state[d] = std::copysign(bound * std::pow(ratio, 1.0 / params_.warp[d]), state[d]);
    }
  }
  // swing: what the energy coding codes (FeatureParams::swingState), or null without one.
  void codedRows(const CartPoleState& state, ActiveRows& active, std::size_t previous, const CartPoleState* swing) const
  {
    const auto offset = static_cast<std::uint32_t>(params_.previous_action ? previous * state_rows_ : 0);
    if (!tile_coder_)
    {
      active.rows[0] = static_cast<std::uint32_t>(discretiser_.index(state)) + offset;
      active.count = 1;
      return;
    }
    tile_coder_->activeTiles(state, active.rows.data());
    active.count = tile_coder_->tilings();
    if (second_coder_)
    {
      // The second coding's rows follow the first's.
      second_coder_->activeTiles(state, active.rows.data() + active.count);
      const auto first_rows = static_cast<std::uint32_t>(tile_coder_->tileCount());
      for (unsigned i = active.count; i < 2 * active.count; ++i)
        active.rows[i] += first_rows;
      active.count += tile_coder_->tilings();
    }
    if (swing)
    {
      // The energy coding's rows follow the others'.
      energy_coder_->activeTiles(*swing, active.rows.data() + active.count);
      const auto before = static_cast<std::uint32_t>(energy_first_row_);
      for (unsigned i = active.count; i < active.count + tile_coder_->tilings(); ++i)
        active.rows[i] += before;
      active.count += tile_coder_->tilings();
    }
    for (unsigned i = 0; offset != 0 && i < active.count; ++i)
      active.rows[i] += offset;
  }

  FeatureParams params_;
  Discretiser discretiser_;
  std::optional<TileCoder> tile_coder_;
  std::optional<TileCoder> second_coder_;  // FeatureParams::second_tiles
  std::optional<TileCoder> energy_coder_;  // FeatureParams::energy_tiles
  std::size_t energy_first_row_ = 0;       // the first row of the energy coding's
  std::size_t state_rows_;
  std::size_t row_count_;
  bool warped_ = false;
};

}  // namespace cartpole_qlearning
