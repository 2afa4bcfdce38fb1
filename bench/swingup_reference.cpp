// A hand-written swing-up for the Control Suite's cart-pole (issue 40): energy pumping from
// hanging, and a linear (LQR) catch near upright, on the model and reward a config names. The
// score a known controller gets, to set the learner's beside: a reference for the benchmark,
// not part of the product (nothing installs or links it).
//
// Energy: E = 1/2 J theta_dot^2 + m g l cos(theta) (J = 4/3 m l^2, a uniform pole about its
// hinge), E_up = m g l upright at rest. The effort pushes E towards E_up: a cart acceleration a
// changes E at a rate proportional to theta_dot cos(theta) a, with the sign of the model's own
// response (found from the linearisation below, so that it holds for either engine's sign
// conventions), plus a spring and damper that keep the cart near the rail's centre.
// Catch: within catch_angle of upright, u = -K s, K the discrete LQR of the model linearised
// about upright by central differences of one step (the engine's own step, tau and all).
//
// usage: swingup_reference CONFIG [EPISODES] [SEED]   (CONFIG e.g. config/swingup.yaml)
// prints: reference episodes=N mean_return=R lowest=L highest=H
#include "cartpole_qlearning/io/yaml_parameters.h"
#include "cartpole_qlearning/learning/cartpole_task.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/simulation/physics_engines.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

namespace
{
using cartpole_qlearning::CartPoleSimulation;
using cartpole_qlearning::CartPoleState;

struct Linearised
{
  Eigen::Matrix4d a;
  Eigen::Vector4d b;
};

// One step's state from `state` under effort `u`, on the engine itself.
Eigen::Vector4d stepFrom(CartPoleSimulation& simulation, const Eigen::Vector4d& state, double u)
{
  CartPoleState s;
  for (int i = 0; i < 4; ++i)
    s[i] = state[i];
  simulation.reset(s);
  const CartPoleState& next = simulation.step(u);
  return Eigen::Vector4d(next[0], next[1], next[2], next[3]);
}

Linearised linearise(CartPoleSimulation simulation)
{
  const double h = 1e-5;
  Linearised model;
  for (int j = 0; j < 4; ++j)
  {
    Eigen::Vector4d plus = Eigen::Vector4d::Zero();
    plus[j] = h;
    model.a.col(j) = (stepFrom(simulation, plus, 0.0) - stepFrom(simulation, -plus, 0.0)) / (2 * h);
  }
  const double du = 1e-3;
  model.b = (stepFrom(simulation, Eigen::Vector4d::Zero(), du) - stepFrom(simulation, Eigen::Vector4d::Zero(), -du)) /
            (2 * du);
  return model;
}

// The discrete LQR gain of the state costs q and effort cost r, by iterating the Riccati equation.
Eigen::RowVector4d lqrGain(const Linearised& m, const Eigen::Vector4d& q, double r)
{
  const Eigen::Matrix4d costs = q.asDiagonal();
  Eigen::Matrix4d p = costs;
  Eigen::RowVector4d k = Eigen::RowVector4d::Zero();
  for (int i = 0; i < 20000; ++i)
  {
    k = (m.b.transpose() * p * m.a) / (r + m.b.dot(p * m.b));
    const Eigen::Matrix4d next = costs + m.a.transpose() * p * (m.a - m.b * k);
    if ((next - p).cwiseAbs().maxCoeff() < 1e-12)
      break;
    p = next;
  }
  return k;
}

struct Controller
{
  Eigen::RowVector4d k;
  double sign = 1.0;  // of the pole's response to the cart's push: d theta_dot / d u
  double mass = 0.1, length = 0.5, gravity = 9.81, force = 10.0;
  double pump = 50.0;        // [N per J rad/s] how hard energy is pumped
  double centre = 6.0;       // [N/m] the cart's spring towards the centre while swinging
  double centre_damp = 6.0;  // [N s/m] and its damper
  double catch_angle = 0.8;  // [rad] the LQR's region

  double effort(const CartPoleState& s) const
  {
    const double theta = std::remainder(s[2], 2.0 * M_PI);
    if (std::fabs(theta) < catch_angle)
    {
      const Eigen::Vector4d x(s[0], s[1], theta, s[3]);
      return std::clamp(-k.dot(x), -force, force);
    }
    const double inertia = 4.0 / 3.0 * mass * length * length;
    const double energy = 0.5 * inertia * s[3] * s[3] + mass * gravity * length * std::cos(theta);
    const double up = mass * gravity * length;
    const double u = pump * (up - energy) * sign * s[3] * std::cos(theta) - centre * s[0] - centre_damp * s[1];
    return std::clamp(u, -force, force);
  }
};
}  // namespace

int main(int argc, char** argv)
{
  using namespace cartpole_qlearning;
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: swingup_reference CONFIG [EPISODES] [SEED]\n");
    return 2;
  }
  try
  {
    const TrainingConfig config = readTrainingConfig(*loadYamlParameters(argv[1]));
    const unsigned episodes = argc > 2 ? static_cast<unsigned>(std::atoi(argv[2])) : 10;
    const std::uint64_t seed = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 0;
    CartPoleSimulation simulation =
        makeSimulation(config.physics, config.engine, config.start_state_bound, seed, config.perturbations);
    const Linearised model = linearise(simulation);
    Controller controller;
    controller.k = lqrGain(model, Eigen::Vector4d(1.0, 0.1, 10.0, 0.1), 0.1);
    controller.sign = model.b[3] > 0 ? 1.0 : -1.0;
    controller.mass = config.physics.mass_pole;
    controller.length = config.physics.half_length;
    controller.gravity = config.physics.gravity;
    controller.force = config.physics.force_mag;
    if (const char* pump = std::getenv("REFERENCE_PUMP"))
      controller.pump = std::atof(pump);
    if (const char* angle = std::getenv("REFERENCE_CATCH"))
      controller.catch_angle = std::atof(angle);
    if (const char* centre = std::getenv("REFERENCE_CENTRE"))
      controller.centre = controller.centre_damp = std::atof(centre);

    simulation.setStart(config.task.start(config.start_state_bound));
    const CartPoleTask task(config.task);
    double sum = 0.0, lowest = 1e300, highest = -1e300;
    for (unsigned e = 0; e < episodes; ++e)
    {
      CartPoleState state = simulation.resetRandom();
      double score = 0.0;
      for (unsigned step = 1;; ++step)
      {
        const double u = controller.effort(state);
        state = simulation.step(u);
        const StepOutcome outcome = task.evaluate(state, step, u);
        score += outcome.score;
        if (outcome.done())
          break;
      }
      sum += score;
      lowest = std::min(lowest, score);
      highest = std::max(highest, score);
    }
    std::printf("reference episodes=%u mean_return=%.1f lowest=%.1f highest=%.1f\n", episodes, sum / episodes, lowest,
                highest);
    return 0;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "swingup_reference: %s\n", e.what());
    return 2;
  }
}
