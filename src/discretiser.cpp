#include "cartpole_qlearning/discretiser.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
const char* const kDimensionNames[kStateDimensions] = {"x", "x_dot", "theta", "theta_dot"};
}  // namespace

std::string DiscretiserParams::validate() const
{
  std::ostringstream out;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (bins[d] < 1 || bins[d] > kMaxBinsPerDimension)
    {
      out << "bins[" << d << "] (" << kDimensionNames[d] << ") = " << bins[d] << " is not allowed (must be in [1, "
          << kMaxBinsPerDimension << "])";
      return out.str();
    }
    if (bins[d] > 1 && !(std::isfinite(lower[d]) && std::isfinite(upper[d]) && lower[d] < upper[d]))
    {
      out << "lower_bounds[" << d << "], upper_bounds[" << d << "] (" << kDimensionNames[d] << ") = " << lower[d]
          << ", " << upper[d] << " are not allowed (must be finite with lower < upper)";
      return out.str();
    }
  }
  std::uint64_t states = 1;
  for (const unsigned b : bins)
    states *= b;  // at most 1000^4: no overflow
  if (states > kMaxStates)
  {
    out << "bins give " << states << " states, more than the " << kMaxStates << " allowed";
    return out.str();
  }
  return "";
}

bool DiscretiserParams::operator==(const DiscretiserParams& other) const
{
  // Bounds of an ignored (1-bin) dimension play no part in the mapping.
  if (bins != other.bins)
    return false;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (bins[d] > 1 && (lower[d] != other.lower[d] || upper[d] != other.upper[d]))
      return false;
  }
  return true;
}

Discretiser::Discretiser(const DiscretiserParams& params) : params_(params), state_count_(1)
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
  for (unsigned b : params_.bins)
    state_count_ *= b;
}

unsigned Discretiser::bin(std::size_t dimension, double value) const
{
  const unsigned n = params_.bins[dimension];
  if (n == 1)
    return 0;
  return uniformBin(value, params_.lower[dimension], params_.upper[dimension], n);
}

std::size_t Discretiser::index(const CartPoleState& state) const
{
  std::size_t row = 0;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
    row = row * params_.bins[d] + bin(d, state[d]);
  return row;
}

}  // namespace cartpole_qlearning
