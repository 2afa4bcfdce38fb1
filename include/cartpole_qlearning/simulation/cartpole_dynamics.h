// Cart-pole equations of motion, with the model and constants of Gymnasium's CartPole-v1.
// No ROS here: the simulator node, the headless trainer and the tests all step this class.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>

namespace cartpole_qlearning
{
// x [m], x_dot [m/s], theta [rad] (0 upright, positive leaning toward +x), theta_dot [rad/s].
using CartPoleState = Eigen::Vector4d;
constexpr std::size_t kStateDimensions = 4;

// The state dimensions by name, in the order of CartPoleState: "x", "x_dot", "theta", "theta_dot".
// stateDimension throws std::invalid_argument naming the allowed ones; stateDimensionName gives
// "?" past the last.
std::size_t stateDimension(const std::string& name);
const char* stateDimensionName(std::size_t dimension);

enum class Integrator
{
  Euler,              // Gymnasium's default: positions advance with the old velocities
  SemiImplicitEuler,  // Gymnasium's "semi-implicit euler": velocities first, positions with the new ones
  Rk4                 // classic fourth-order Runge-Kutta over one tau
};

// Parses "euler", "semi_implicit_euler" or "rk4"; throws std::invalid_argument otherwise.
Integrator integratorFromString(const std::string& name);
std::string toString(Integrator integrator);

struct CartPoleParams
{
  double gravity = 9.8;      // [m/s^2]
  double mass_cart = 1.0;    // [kg]
  double mass_pole = 0.1;    // [kg]
  double half_length = 0.5;  // [m] half the pole's length (Gymnasium's "length")
  double force_mag = 10.0;   // [N] largest force the actuator applies; commands are clamped to it
  double tau = 0.02;         // [s] one step
  Integrator integrator = Integrator::Euler;
  // Friction, as in Barto, Sutton and Anderson's original equations (1983): of the cart on the
  // track [N, against the cart's velocity's sign] and of the pole on its hinge [N m s]. 0: none
  // (Gymnasium's model; their paper used 0.0005 and 0.000002).
  double cart_friction = 0.0;
  double pole_friction = 0.0;

  // Empty when valid, else a message naming the first bad field, its value and the allowed range.
  std::string validate() const;
};

class CartPoleDynamics
{
public:
  explicit CartPoleDynamics(const CartPoleParams& params = CartPoleParams());

  const CartPoleParams& params() const
  {
    return params_;
  }

  // Time derivative of the state under a force [N] (not clamped here).
  CartPoleState derivative(const CartPoleState& state, double force) const;

  // The state one tau later with the force held constant over the step (not clamped here).
  CartPoleState step(const CartPoleState& state, double force) const;

  // The force clamped to +-force_mag.
  double clampForce(double force) const;

private:
  CartPoleParams params_;
};

}  // namespace cartpole_qlearning
