// Maps a continuous cart-pole state to one Q-table row with uniform bins per dimension.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace cartpole_qlearning
{
constexpr unsigned kMaxBinsPerDimension = 1000;
// The most states a table may have (all dimensions' bins multiplied): a config or a file that
// asks for more is refused before anything is allocated (10 million states of 2 actions take
// 160 MB).
constexpr std::uint64_t kMaxStates = 10000000;

struct DiscretiserParams
{
  // Bins per dimension (x, x_dot, theta, theta_dot). A dimension with 1 bin is ignored.
  std::array<unsigned, kStateDimensions> bins{{1, 1, 6, 12}};
  // Values below lower / at or above upper go to the first / last bin (clipping).
  std::array<double, kStateDimensions> lower{{-2.4, -3.0, -0.20943951023931953, -0.8726646259971648}};
  std::array<double, kStateDimensions> upper{{2.4, 3.0, 0.20943951023931953, 0.8726646259971648}};

  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
  bool operator==(const DiscretiserParams& other) const;
};

// A uniform grid's parameters, as bins and tiles both give them (counts named by count_key:
// "bins" or "tiles"; a dimension with count 1 is ignored and its bounds are not read). Empty
// when valid, else a message naming the first bad count or bounds.
std::string uniformGridError(const char* count_key, const std::array<unsigned, kStateDimensions>& counts,
                             const std::array<double, kStateDimensions>& lower,
                             const std::array<double, kStateDimensions>& upper);
// Whether two grids map states alike: the same counts, and the same bounds where a count is above 1.
bool sameUniformGrid(const std::array<unsigned, kStateDimensions>& counts,
                     const std::array<double, kStateDimensions>& lower,
                     const std::array<double, kStateDimensions>& upper,
                     const std::array<unsigned, kStateDimensions>& other_counts,
                     const std::array<double, kStateDimensions>& other_lower,
                     const std::array<double, kStateDimensions>& other_upper);

// The bin of a value among n uniform bins over [lower, upper): bin i covers
// [lower + i*w, lower + (i+1)*w) with w = (upper - lower) / n; values below lower (and NaN) go to
// bin 0, values at or above upper to bin n - 1. A value on an edge always lands in the bin that
// starts there, even where the division rounds across it. n >= 1, lower < upper.
// width: (upper - lower) / n, computed once by a caller that bins many values (the same
// quotient every time: the same bins).
inline unsigned uniformBin(double value, double lower, double upper, unsigned n, double width)
{
  if (!(value >= lower))  // below the range, or NaN
    return 0;
  if (value >= upper)
    return n - 1;
  unsigned i = static_cast<unsigned>((value - lower) / width);
  if (i >= n)
    i = n - 1;
  if (value < lower + i * width)
    --i;
  else if (i + 1 < n && value >= lower + (i + 1) * width)
    ++i;
  return i;
}
inline unsigned uniformBin(double value, double lower, double upper, unsigned n)
{
  return uniformBin(value, lower, upper, n, (upper - lower) / n);
}

class Discretiser
{
public:
  explicit Discretiser(const DiscretiserParams& params = DiscretiserParams());

  const DiscretiserParams& params() const
  {
    return params_;
  }

  // Product of the bin counts: the number of Q-table rows.
  std::size_t stateCount() const
  {
    return state_count_;
  }

  // The bin of one dimension's value (uniformBin over that dimension's bins and bounds). No allocation.
  // Inline, as index() is: every step of training and of the robustness suite bins a state.
  unsigned bin(std::size_t dimension, double value) const
  {
    const unsigned n = params_.bins[dimension];
    if (n == 1)
      return 0;
    return uniformBin(value, params_.lower[dimension], params_.upper[dimension], n, widths_[dimension]);
  }

  // The row of a state: the bins combined in mixed radix, first dimension most significant.
  std::size_t index(const CartPoleState& state) const
  {
    std::size_t row = 0;
    for (std::size_t d = 0; d < kStateDimensions; ++d)
      row = row * params_.bins[d] + bin(d, state[d]);
    return row;
  }

private:
  DiscretiserParams params_;
  std::size_t state_count_;
  // Each dimension's bin width, (upper - lower) / bins: the quotient uniformBin would compute on
  // every call, computed once.
  std::array<double, kStateDimensions> widths_{};
};

}  // namespace cartpole_qlearning
