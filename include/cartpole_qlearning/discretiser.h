// Maps a continuous cart-pole state to one Q-table row with uniform bins per dimension.
#pragma once

#include "cartpole_qlearning/cartpole_dynamics.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace cartpole_qlearning
{
constexpr std::size_t kStateDimensions = 4;
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

  // The bin of one dimension's value. Bin i covers [lower + i*w, lower + (i+1)*w) with
  // w = (upper - lower) / bins; a NaN goes to bin 0. No allocation.
  unsigned bin(std::size_t dimension, double value) const;

  // The row of a state: the bins combined in mixed radix, first dimension most significant.
  std::size_t index(const CartPoleState& state) const;

private:
  DiscretiserParams params_;
  std::size_t state_count_;
};

}  // namespace cartpole_qlearning
