#include "cartpole_qlearning/learning/discretiser.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
std::string uniformGridError(const char* count_key, const std::array<unsigned, kStateDimensions>& counts,
                             const std::array<double, kStateDimensions>& lower,
                             const std::array<double, kStateDimensions>& upper)
{
  std::ostringstream out;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (counts[d] < 1 || counts[d] > kMaxBinsPerDimension)
    {
      out << count_key << "[" << d << "] (" << stateDimensionName(d) << ") = " << counts[d]
          << " is not allowed (must be in [1, " << kMaxBinsPerDimension << "])";
      return out.str();
    }
    if (counts[d] > 1 && !(std::isfinite(lower[d]) && std::isfinite(upper[d]) && lower[d] < upper[d]))
    {
      out << "lower_bounds[" << d << "], upper_bounds[" << d << "] (" << stateDimensionName(d) << ") = " << lower[d]
          << ", " << upper[d] << " are not allowed (must be finite with lower < upper)";
      return out.str();
    }
  }
  return "";
}

bool sameUniformGrid(const std::array<unsigned, kStateDimensions>& counts,
                     const std::array<double, kStateDimensions>& lower,
                     const std::array<double, kStateDimensions>& upper,
                     const std::array<unsigned, kStateDimensions>& other_counts,
                     const std::array<double, kStateDimensions>& other_lower,
                     const std::array<double, kStateDimensions>& other_upper)
{
  // Bounds of an ignored (count 1) dimension play no part in the mapping.
  if (counts != other_counts)
    return false;
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    if (counts[d] > 1 && (lower[d] != other_lower[d] || upper[d] != other_upper[d]))
      return false;
  }
  return true;
}

std::string DiscretiserParams::validate() const
{
  const std::string error = uniformGridError("bins", bins, lower, upper);
  if (!error.empty())
    return error;
  std::uint64_t states = 1;
  for (const unsigned b : bins)
    states *= b;  // at most 1000^4: no overflow
  if (states > kMaxStates)
    return "bins give " + std::to_string(states) + " states, more than the " + std::to_string(kMaxStates) + " allowed";
  return "";
}

bool DiscretiserParams::operator==(const DiscretiserParams& other) const
{
  return sameUniformGrid(bins, lower, upper, other.bins, other.lower, other.upper);
}

Discretiser::Discretiser(const DiscretiserParams& params) : params_(params), state_count_(1)
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
  for (std::size_t d = 0; d < kStateDimensions; ++d)
  {
    state_count_ *= params_.bins[d];
    widths_[d] = (params_.upper[d] - params_.lower[d]) / params_.bins[d];
  }
}

}  // namespace cartpole_qlearning
