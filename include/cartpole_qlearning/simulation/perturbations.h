// What a real cart-pole does that the ideal model does not: it answers a command late, its
// sensors are noisy, its masses, pole and motor are not the model's, and it gets pushed. The
// core simulation applies these (CartPoleSimulation), so that the sim node, train_headless and
// the robustness suite share one model, reproducible by seed. All off by default: the ideal
// model, bit for bit.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/simulation/physics_engine.h"
#include "cartpole_qlearning/common/random.h"

#include <array>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// A factor of a configured value, drawn per episode uniformly in [low, high].
struct ScaleRange
{
  double low = 1.0;
  double high = 1.0;

  bool varies() const
  {
    return !(low == 1.0 && high == 1.0);
  }
};

struct PerturbationParams
{
  // Actuation delay [steps]: a command takes effect this many steps after the state it answers
  // (a controller over topics on ros_control hardware: one control period). Until then the
  // earlier commands act; after a reset, zero. Drawn per episode, uniformly among the whole
  // numbers in [delay_steps, delay_steps_max] (one value when they are equal).
  unsigned delay_steps = 0;
  unsigned delay_steps_max = 0;
  // Sensor noise: each observed value is the true one plus Gaussian noise of standard deviation
  // noise_std[i] + noise_fraction[i] * |value| ([m, m/s, rad, rad/s]; a fraction). The true
  // state, which the physics integrates, is untouched.
  std::array<double, 4> noise_std{};
  std::array<double, 4> noise_fraction{};
  // Physics drawn per episode, each as a factor of the configured value.
  ScaleRange mass_cart;
  ScaleRange mass_pole;
  ScaleRange half_length;
  ScaleRange motor;  // the force the motor applies for a command (0.8: 20 % weaker)
  // Random pushes: at each step, with this probability, push_force [N] in a random direction
  // acts on the cart for that step, beside the motor's force.
  double push_probability = 0.0;
  double push_force = 0.0;

  bool noisy() const;
  bool pushes() const
  {
    return push_probability > 0.0 && push_force != 0.0;
  }
  // Something is drawn at each episode's start (the delay or a physics factor).
  bool drawnPerEpisode() const;
  // Random numbers are drawn at steps (noise, pushes), not only at resets: an episode then meets
  // the draws of every step before it.
  bool drawsWhileStepping() const
  {
    return noisy() || pushes();
  }
  // What a step costs, in steps of the unperturbed model: a noisy value draws a normal (a log, a
  // cosine and two draws: about half the physics' step, perf on the shipped suite), a push a draw.
  double stepCost() const;
  bool any() const;
  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
};

// A key of the config's perturbations section and the field it sets, by the form its value takes.
// The config's reader and a table's trained_with go through perturbationKeys(), in its order: a new
// perturbation of one of these forms is its field, its line there, and what the simulation does.
struct PerturbationKey
{
  enum class Form
  {
    Steps,       // a whole number of steps in [0, 1000], or [low, high] of them: `low` and `high`
    Dimensions,  // one number per state value [x, x_dot, theta, theta_dot]: `dimensions`
    Factors,     // [low, high], a factor drawn per episode: `factors`
    Number       // `number`
  };
  std::string name;
  Form form = Form::Number;
  unsigned PerturbationParams::*low = nullptr;
  unsigned PerturbationParams::*high = nullptr;
  std::array<double, 4> PerturbationParams::*dimensions = nullptr;
  ScaleRange PerturbationParams::*factors = nullptr;
  double PerturbationParams::*number = nullptr;
};
const std::vector<PerturbationKey>& perturbationKeys();

// The stream of the per-episode physics draws and the pushes (random.h has the others): its own,
// so that turning perturbations on changes neither the start states nor exploration.
constexpr std::uint64_t kPerturbationStream = 3;

// The factors of one episode's physics over the configured (the motor factor scales commands
// after the drive's clamp), and its delay: drawn in that order (delay, mass_cart, mass_pole,
// half_length, motor), a range that is off drawing nothing.
EpisodeFactors drawEpisodeFactors(const PerturbationParams& perturbations, RandomStream& rng, unsigned& delay_steps);

// A command line that delivers each command delay_steps steps after it was given.
class ActuationDelay
{
public:
  explicit ActuationDelay(unsigned steps = 0);
  // Empties the line (zero acts until new commands come through), now `steps` long.
  void reset(unsigned steps);
  void reset()
  {
    reset(steps_);
  }
  unsigned steps() const
  {
    return steps_;
  }
  // Takes the command for this step and returns the one that acts now.
  double apply(double command)
  {
    if (steps_ == 0)
      return command;
    // A ring of steps_ commands: the oldest acts now and the newest takes its place (a deque
    // allocated a block every few dozen steps).
    const double acting = line_[next_];
    line_[next_] = command;
    next_ = next_ + 1 == steps_ ? 0 : next_ + 1;
    return acting;
  }

private:
  unsigned steps_;
  std::vector<double> line_;
  unsigned next_ = 0;  // the oldest command's place in line_
};

// What is on, for a log line: "delay 1 step (0.02 s), noise_std [0.01, 0, 0.0087, 0], motor x[0.8, 0.8]"
// (tau: the step [s]); "none" when nothing is.
std::string describePerturbations(const PerturbationParams& perturbations, double tau);

// Adds the sensor noise to a state (the draws come from rng, one normal per noisy value).
CartPoleState addSensorNoise(const CartPoleState& state, const PerturbationParams& perturbations, RandomStream& rng);

}  // namespace cartpole_qlearning
