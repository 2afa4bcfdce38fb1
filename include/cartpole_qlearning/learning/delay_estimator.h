// How many steps late a robot carries out its commands, found from how its states answer them.
// Each step, every delay d in [0, kLargestFoundDelay] is a hypothesis: the state observed now is
// the state before it advanced by the model under the command sent d steps before that. The
// hypothesis whose predictions miss least (velocities, where a command shows within the step;
// positions follow a step later) is the robot's delay once it is clearly the best over recent
// steps. A heavier pole, a weaker motor, noisy sensors or a push make every hypothesis miss by
// about as much; a command one step off misses by a whole command's worth each time the command
// changes, so the right delay stands out after a few dozen decisions of a balancing table.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

namespace cartpole_qlearning
{
// The largest delay looked for: ros_control answers one period late, a busy bridge two.
constexpr unsigned kLargestFoundDelay = 3;

class DelayEstimator
{
public:
  // model: the physics the table learnt (its equations, commands clamped to its force_mag).
  explicit DelayEstimator(const CartPoleParams& model);

  // A start (a reset, an episode that begins): the next state does not follow from the last one
  // by the model, and the commands before it are taken as 0 (the robot stood still).
  void begin(const CartPoleState& start);
  // The state observed now, after the commands sent so far.
  void observed(const CartPoleState& state);
  // The command just sent.
  void sent(double effort);

  // The delay, once one hypothesis misses clearly least (kept until another does); none before.
  std::optional<unsigned> estimate() const
  {
    return estimate_;
  }
  // The commands sent, newest first: sentBefore(0) the last one, 0 before the start.
  double sentBefore(std::size_t steps) const;
  // Each hypothesis's recent squared miss (for the tests and the log).
  const std::array<double, kLargestFoundDelay + 1>& misses() const
  {
    return misses_;
  }

private:
  CartPoleDynamics model_;
  std::vector<double> sent_;  // a ring of the last kLargestFoundDelay + 1 commands
  std::size_t newest_ = 0;
  std::optional<CartPoleState> last_;  // the state the next one follows from
  std::array<double, kLargestFoundDelay + 1> misses_{};
  unsigned telling_steps_ = 0;  // steps where the hypotheses' commands differed
  std::optional<unsigned> estimate_;
};

}  // namespace cartpole_qlearning
