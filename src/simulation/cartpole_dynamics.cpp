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
  for (const auto& [name, value] : {std::pair<const char*, double>{"cart_friction", cart_friction},
                                    {"pole_friction", pole_friction},
                                    {"rail_limit", rail_limit}})
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

CartPoleState CartPoleDynamics::derivativeAtEnd(const CartPoleState& state, double force) const
{
  // MuJoCo's soft limit (solref 0.08 1, solimp's largest impedance 0.95) in the stop's own
  // direction: outward is +x at the right end, -x at the left.
  constexpr double kTimeConstant = 0.08;
  constexpr double kImpedance = 0.95;
  constexpr double kDamping = 2.0 / (kImpedance * kTimeConstant);
  constexpr double kStiffness = 1.0 / (kImpedance * kTimeConstant * kTimeConstant);
  const double outward = state[0] > 0.0 ? 1.0 : -1.0;
  const double past = outward * state[0] - params_.rail_limit;
  const double speed = outward * state[1];
  const CartPoleState free = freeDerivative(state, force);
  const double free_acc = outward * free[1];
  const double wanted = (1.0 - kImpedance) * free_acc - kImpedance * (kDamping * speed + kStiffness * past);
  if (wanted >= free_acc)  // the stop only pushes the cart back, never pulls it on
    return free;
  // The cart's acceleration per newton on it, with the pole's reaction through the hinge (the
  // equations are linear in the force).
  const double total_mass = params_.mass_pole + params_.mass_cart;
  const double cos_sq = std::cos(state[2]) * std::cos(state[2]);
  const double per_newton =
      (1.0 + params_.mass_pole * cos_sq / (total_mass * 4.0 / 3.0 - params_.mass_pole * cos_sq)) / total_mass;
  return freeDerivative(state, force + outward * (wanted - free_acc) / per_newton);
}

CartPoleState CartPoleDynamics::rk4Step(const CartPoleState& state, double force) const
{
  const double tau = params_.tau;
  const CartPoleState d = derivative(state, force);
  const CartPoleState k2 = derivative(state + 0.5 * tau * d, force);
  const CartPoleState k3 = derivative(state + 0.5 * tau * k2, force);
  const CartPoleState k4 = derivative(state + tau * k3, force);
  return state + (tau / 6.0) * (d + 2.0 * k2 + 2.0 * k3 + k4);
}

}  // namespace cartpole_qlearning
