#include "cartpole_qlearning/common/random.h"

#include <cmath>

namespace cartpole_qlearning
{
namespace
{
// SplitMix64: turns (seed, stream) into a well-mixed engine seed, so that seeds 0, 1, 2 and the
// two streams of one seed do not start from related engine states.
std::uint64_t splitMix64(std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}
}  // namespace

RandomStream::RandomStream(std::uint64_t seed, std::uint64_t stream_id)
  : engine_(splitMix64(splitMix64(seed) ^ stream_id))
{
}

double RandomStream::uniform(double low, double high)
{
  return low + (high - low) * uniform01();
}

double RandomStream::normal()
{
  const double u1 = 1.0 - uniform01();  // in (0, 1], so the log is finite
  const double u2 = uniform01();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

std::uint64_t RandomStream::uniformIndex(std::uint64_t n)
{
  // Rejection sampling: draws past the largest multiple of n are thrown away.
  const std::uint64_t limit = UINT64_MAX - UINT64_MAX % n;
  std::uint64_t draw = engine_();
  while (draw >= limit)
    draw = engine_();
  return draw % n;
}

}  // namespace cartpole_qlearning
