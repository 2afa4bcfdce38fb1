// Seeded random streams whose draws are defined here, not by the standard library's
// distributions (those differ between libstdc++ and libc++), so that a seed gives the same
// run on every machine. The environment (start states) and the agent (exploration) each own
// a stream, as the simulator node and the controller node each own theirs.
#pragma once

#include <cstdint>
#include <random>

namespace cartpole_qlearning
{
class RandomStream
{
public:
  // stream_id keeps the environment's and the agent's draws independent for one seed.
  RandomStream(std::uint64_t seed, std::uint64_t stream_id);

  // Uniform in [0, 1), 53 random bits. Inline: the simulation draws it every step (pushes).
  double uniform01()
  {
    return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  // Uniform in [low, high).
  double uniform(double low, double high);
  // Standard normal (Box-Muller, two uniform draws per value).
  double normal();
  // Uniform integer in [0, n), without modulo bias; n must be > 0.
  std::uint64_t uniformIndex(std::uint64_t n);

private:
  std::mt19937_64 engine_;
};

// The stream ids used by the simulator / headless environment and by the learning agent.
constexpr std::uint64_t kEnvironmentStream = 0;
constexpr std::uint64_t kAgentStream = 1;
// Sensor and actuator noise of the simulator node: its own stream, so that adding noise does
// not change the start states.
constexpr std::uint64_t kNoiseStream = 2;

}  // namespace cartpole_qlearning
