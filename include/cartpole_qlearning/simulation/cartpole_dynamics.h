// Cart-pole equations of motion, with the model and constants of Gymnasium's CartPole-v1.
// No ROS here: the simulator node, the headless trainer and the tests all step this class.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
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
  // [m] the rail's ends at +-this (0: no ends, CartPole-v1's track, whose task ends at 2.4 m). Past an
  // end a stop pushes the cart back as MuJoCo's soft joint limit does with the Suite's solreflimit
  // (0.08 s, damping ratio 1) and impedance 0.95: the cart's acceleration becomes
  // 0.05 a_free - 0.95 (b v + k r) (r past the end, v outwards, b = 2 / (0.95 x 0.08),
  // k = 1 / (0.95 x 0.08^2)), never pulling it outwards. A continuous force, so that RK4 steps it.
  double rail_limit = 0.0;

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
  // Inline (below, with derivative): the physics is a third of a greedy step's time, and a call
  // across the library boundary was a good part of it.
  CartPoleState step(const CartPoleState& state, double force) const;

  // step(state, forces[i]) into out[i] for each of n forces from one state, the same bits, with
  // the pole's sine and cosine worked out once where the integrator allows (Euler's two kinds, the
  // cart within the rail): DelayEstimator steps every delay it weighs from the same state.
  void stepEach(const CartPoleState& state, const double* forces, std::size_t n, CartPoleState* out) const;

  // How much of a step's change of a velocity shows in the same step's change of its position, as
  // a share of tau x that change: none under Gymnasium's Euler (positions advance with the old
  // velocity), all of it under the semi-implicit one, about half under RK4. A model whose velocity
  // change is corrected afterwards (DelayPredictor's fit) moves the position by this much of it.
  double velocityChangeInPosition() const
  {
    switch (params_.integrator)
    {
      case Integrator::Euler:
        return 0.0;
      case Integrator::SemiImplicitEuler:
        return 1.0;
      case Integrator::Rk4:
        break;
    }
    return 0.5;
  }

  // The force clamped to +-force_mag.
  double clampForce(double force) const
  {
    return std::clamp(force, -params_.force_mag, params_.force_mag);
  }

private:
  // step() under Integrator::Rk4.
  CartPoleState rk4Step(const CartPoleState& state, double force) const;
  // The derivative with the rail's stop acting (the cart past an end).
  CartPoleState derivativeAtEnd(const CartPoleState& state, double force) const;
  // The derivative without the rail's ends; the second with cos and sin of the state's theta given.
  CartPoleState freeDerivative(const CartPoleState& state, double force) const;
  CartPoleState freeDerivative(const CartPoleState& state, double force, double costheta, double sintheta) const;
  // An Euler step (either kind, by the integrator) from the state and its derivative.
  CartPoleState eulerStep(const CartPoleState& state, const CartPoleState& d) const;

  CartPoleParams params_;
};

inline CartPoleState CartPoleDynamics::derivative(const CartPoleState& state, double force) const
{
  if (params_.rail_limit > 0.0 && std::fabs(state[0]) > params_.rail_limit)
    return derivativeAtEnd(state, force);
  return freeDerivative(state, force);
}

inline CartPoleState CartPoleDynamics::freeDerivative(const CartPoleState& state, double force) const
{
  return freeDerivative(state, force, std::cos(state[2]), std::sin(state[2]));
}

inline CartPoleState CartPoleDynamics::freeDerivative(const CartPoleState& state, double force, double costheta,
                                                      double sintheta) const
{
  // Written in Gymnasium's order of operations so that Euler steps agree with it to the last bits.
  const double total_mass = params_.mass_pole + params_.mass_cart;
  const double polemass_length = params_.mass_pole * params_.half_length;
  const double theta_dot = state[3];
  if (params_.cart_friction != 0.0 || params_.pole_friction != 0.0)
  {
    // Barto, Sutton and Anderson's equations with their friction terms (kept apart, so that the
    // frictionless model stays Gymnasium's operation for operation).
    const double sign_x_dot = state[1] > 0.0 ? 1.0 : (state[1] < 0.0 ? -1.0 : 0.0);
    const double temp =
        (force + polemass_length * (theta_dot * theta_dot) * sintheta - params_.cart_friction * sign_x_dot) /
        total_mass;
    const double thetaacc =
        (params_.gravity * sintheta - costheta * temp - params_.pole_friction * theta_dot / polemass_length) /
        (params_.half_length * (4.0 / 3.0 - params_.mass_pole * (costheta * costheta) / total_mass));
    const double xacc = temp - polemass_length * thetaacc * costheta / total_mass;
    return CartPoleState(state[1], xacc, theta_dot, thetaacc);
  }
  const double temp = (force + polemass_length * (theta_dot * theta_dot) * sintheta) / total_mass;
  const double thetaacc = (params_.gravity * sintheta - costheta * temp) /
                          (params_.half_length * (4.0 / 3.0 - params_.mass_pole * (costheta * costheta) / total_mass));
  const double xacc = temp - polemass_length * thetaacc * costheta / total_mass;
  return CartPoleState(state[1], xacc, theta_dot, thetaacc);
}

inline CartPoleState CartPoleDynamics::step(const CartPoleState& state, double force) const
{
  // RK4 (four derivatives) out of line: the Euler steps then stay small enough to be inlined.
  if (params_.integrator == Integrator::Rk4)
    return rk4Step(state, force);
  return eulerStep(state, derivative(state, force));
}

inline void CartPoleDynamics::stepEach(const CartPoleState& state, const double* forces, std::size_t n,
                                       CartPoleState* out) const
{
  if (params_.integrator == Integrator::Rk4 || (params_.rail_limit > 0.0 && std::fabs(state[0]) > params_.rail_limit))
  {
    for (std::size_t i = 0; i < n; ++i)
      out[i] = step(state, forces[i]);
    return;
  }
  const double costheta = std::cos(state[2]);
  const double sintheta = std::sin(state[2]);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = eulerStep(state, freeDerivative(state, forces[i], costheta, sintheta));
}

inline CartPoleState CartPoleDynamics::eulerStep(const CartPoleState& state, const CartPoleState& d) const
{
  const double tau = params_.tau;
  if (params_.integrator == Integrator::Euler)
    return CartPoleState(state[0] + tau * state[1], state[1] + tau * d[1], state[2] + tau * state[3],
                         state[3] + tau * d[3]);
  const double x_dot = state[1] + tau * d[1];
  const double theta_dot = state[3] + tau * d[3];
  return CartPoleState(state[0] + tau * x_dot, x_dot, state[2] + tau * theta_dot, theta_dot);
}

}  // namespace cartpole_qlearning
