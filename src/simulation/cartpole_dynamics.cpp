#include "cartpole_qlearning/simulation/cartpole_dynamics.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
const char* const kDimensionNames[kStateDimensions] = {"x", "x_dot", "theta", "theta_dot"};
}  // namespace

std::size_t stateDimension(const std::string& name)
{
  for (std::size_t d = 0; d < kStateDimensions; ++d)
    if (name == kDimensionNames[d])
      return d;
  throw std::invalid_argument("'" + name + "' is not a state dimension (allowed: x, x_dot, theta, theta_dot)");
}

const char* stateDimensionName(std::size_t dimension)
{
  return dimension < kStateDimensions ? kDimensionNames[dimension] : "?";
}

Integrator integratorFromString(const std::string& name)
{
  if (name == "euler")
    return Integrator::Euler;
  if (name == "semi_implicit_euler")
    return Integrator::SemiImplicitEuler;
  if (name == "rk4")
    return Integrator::Rk4;
  throw std::invalid_argument("unknown integrator '" + name + "' (allowed: euler, semi_implicit_euler, rk4)");
}

std::string toString(Integrator integrator)
{
  switch (integrator)
  {
    case Integrator::Euler:
      return "euler";
    case Integrator::SemiImplicitEuler:
      return "semi_implicit_euler";
    case Integrator::Rk4:
      return "rk4";
  }
  return "unknown";
}

std::string CartPoleParams::validate() const
{
  const auto positive = [](const char* name, double value) -> std::string {
    if (std::isfinite(value) && value > 0.0)
      return "";
    std::ostringstream out;
    out << name << " = " << value << " is not allowed (must be finite and > 0)";
    return out.str();
  };
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"cart_friction", cart_friction}, {"pole_friction", pole_friction}})
  {
    if (!(std::isfinite(value) && value >= 0.0))
    {
      std::ostringstream out;
      out << name << " = " << value << " is not allowed (must be finite and >= 0)";
      return out.str();
    }
  }
  for (const auto& check :
       {positive("gravity", gravity), positive("mass_cart", mass_cart), positive("mass_pole", mass_pole),
        positive("half_length", half_length), positive("force_mag", force_mag), positive("tau", tau)})
  {
    if (!check.empty())
      return check;
  }
  return "";
}

CartPoleDynamics::CartPoleDynamics(const CartPoleParams& params) : params_(params)
{
  const std::string error = params_.validate();
  if (!error.empty())
    throw std::invalid_argument(error);
}

CartPoleState CartPoleDynamics::derivative(const CartPoleState& state, double force) const
{
  // Written in Gymnasium's order of operations so that Euler steps agree with it to the last bits.
  const double total_mass = params_.mass_pole + params_.mass_cart;
  const double polemass_length = params_.mass_pole * params_.half_length;
  const double theta = state[2];
  const double theta_dot = state[3];
  const double costheta = std::cos(theta);
  const double sintheta = std::sin(theta);
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

CartPoleState CartPoleDynamics::step(const CartPoleState& state, double force) const
{
  const double tau = params_.tau;
  const CartPoleState d = derivative(state, force);
  CartPoleState next;
  switch (params_.integrator)
  {
    case Integrator::Euler:
      next = CartPoleState(state[0] + tau * state[1], state[1] + tau * d[1], state[2] + tau * state[3],
                           state[3] + tau * d[3]);
      break;
    case Integrator::SemiImplicitEuler: {
      const double x_dot = state[1] + tau * d[1];
      const double theta_dot = state[3] + tau * d[3];
      next = CartPoleState(state[0] + tau * x_dot, x_dot, state[2] + tau * theta_dot, theta_dot);
      break;
    }
    case Integrator::Rk4: {
      const CartPoleState k2 = derivative(state + 0.5 * tau * d, force);
      const CartPoleState k3 = derivative(state + 0.5 * tau * k2, force);
      const CartPoleState k4 = derivative(state + tau * k3, force);
      next = state + (tau / 6.0) * (d + 2.0 * k2 + 2.0 * k3 + k4);
      break;
    }
  }
  return next;
}

double CartPoleDynamics::clampForce(double force) const
{
  return std::clamp(force, -params_.force_mag, params_.force_mag);
}

}  // namespace cartpole_qlearning
