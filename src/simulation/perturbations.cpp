#include "cartpole_qlearning/simulation/perturbations.h"

#include <cmath>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
double draw(const ScaleRange& range, RandomStream& rng)
{
  // No draw when the factor is fixed: a range that is off costs no random number.
  return range.low == range.high ? range.low : rng.uniform(range.low, range.high);
}
}  // namespace

bool PerturbationParams::noisy() const
{
  for (std::size_t i = 0; i < 4; ++i)
  {
    if (noise_std[i] != 0.0 || noise_fraction[i] != 0.0)
      return true;
  }
  return false;
}

bool PerturbationParams::drawnPerEpisode() const
{
  return mass_cart.varies() || mass_pole.varies() || half_length.varies() || motor.varies() ||
         delay_steps_max != delay_steps;
}

double PerturbationParams::stepCost() const
{
  double cost = 1.0;
  for (std::size_t i = 0; i < noise_std.size(); ++i)
    cost += noise_std[i] != 0.0 || noise_fraction[i] != 0.0 ? 0.5 : 0.0;
  if (pushes())
    cost += 0.1;
  return cost;
}

bool PerturbationParams::any() const
{
  return delay_steps > 0 || delay_steps_max > 0 || noisy() || mass_cart.varies() || mass_pole.varies() ||
         half_length.varies() || motor.varies() || pushes();
}

std::string PerturbationParams::validate() const
{
  std::ostringstream out;
  const auto bad = [&](const std::string& name, double value, const char* allowed) {
    out << name << " = " << value << " is not allowed (" << allowed << ")";
    return out.str();
  };
  for (std::size_t i = 0; i < 4; ++i)
  {
    if (!(std::isfinite(noise_std[i]) && noise_std[i] >= 0.0))
      return bad(std::string("noise_std[") + stateDimensionName(i) + "]", noise_std[i], "must be finite and >= 0");
    if (!(std::isfinite(noise_fraction[i]) && noise_fraction[i] >= 0.0))
      return bad(std::string("noise_fraction[") + stateDimensionName(i) + "]", noise_fraction[i],
                 "must be finite and >= 0");
  }
  const std::pair<const char*, const ScaleRange*> ranges[] = {
      {"mass_cart", &mass_cart}, {"mass_pole", &mass_pole}, {"half_length", &half_length}, {"motor", &motor}};
  for (const auto& [name, range] : ranges)
  {
    if (!(std::isfinite(range->low) && range->low > 0.0))
      return bad(std::string(name) + "/low", range->low, "must be finite and > 0");
    if (!(std::isfinite(range->high) && range->high >= range->low))
      return bad(std::string(name) + "/high", range->high, "must be finite and >= low");
  }
  if (delay_steps > 1000)
    return bad("delay_steps", delay_steps, "must be a whole number in [0, 1000]");
  if (delay_steps_max < delay_steps || delay_steps_max > 1000)
    return bad("delay_steps (high)", delay_steps_max, "must be a whole number in [low, 1000]");
  if (!(std::isfinite(push_probability) && push_probability >= 0.0 && push_probability <= 1.0))
    return bad("push_probability", push_probability, "must be in [0, 1]");
  if (!(std::isfinite(push_force) && push_force >= 0.0))
    return bad("push_force", push_force, "must be finite and >= 0");
  return "";
}

const std::vector<PerturbationKey>& perturbationKeys()
{
  using Form = PerturbationKey::Form;
  using P = PerturbationParams;
  static const std::vector<PerturbationKey> keys = [] {
    std::vector<PerturbationKey> list;
    PerturbationKey delay{"delay_steps", Form::Steps};
    delay.low = &P::delay_steps;
    delay.high = &P::delay_steps_max;
    list.push_back(delay);
    for (const auto& [name, field] : {std::pair<const char*, std::array<double, 4> P::*>{"noise_std", &P::noise_std},
                                      {"noise_fraction", &P::noise_fraction}})
    {
      PerturbationKey key{name, Form::Dimensions};
      key.dimensions = field;
      list.push_back(key);
    }
    for (const auto& [name, field] : {std::pair<const char*, ScaleRange P::*>{"mass_cart", &P::mass_cart},
                                      {"mass_pole", &P::mass_pole},
                                      {"half_length", &P::half_length},
                                      {"motor", &P::motor}})
    {
      PerturbationKey key{name, Form::Factors};
      key.factors = field;
      list.push_back(key);
    }
    for (const auto& [name, field] : {std::pair<const char*, double P::*>{"push_probability", &P::push_probability},
                                      {"push_force", &P::push_force}})
    {
      PerturbationKey key{name, Form::Number};
      key.number = field;
      list.push_back(key);
    }
    return list;
  }();
  return keys;
}

EpisodeFactors drawEpisodeFactors(const PerturbationParams& p, RandomStream& rng, unsigned& delay_steps)
{
  delay_steps = p.delay_steps_max == p.delay_steps
                    ? p.delay_steps
                    : p.delay_steps + static_cast<unsigned>(rng.uniformIndex(p.delay_steps_max - p.delay_steps + 1));
  EpisodeFactors factors;
  factors.mass_cart = draw(p.mass_cart, rng);
  factors.mass_pole = draw(p.mass_pole, rng);
  factors.half_length = draw(p.half_length, rng);
  factors.motor = draw(p.motor, rng);
  return factors;
}

ActuationDelay::ActuationDelay(unsigned steps) : steps_(steps)
{
  reset();
}

void ActuationDelay::reset(unsigned steps)
{
  steps_ = steps;
  line_.assign(steps_, 0.0);
  next_ = 0;
}

std::string describePerturbations(const PerturbationParams& p, double tau)
{
  std::ostringstream out;
  const auto item = [&out]() -> std::ostringstream& {
    if (out.tellp() > 0)
      out << ", ";
    return out;
  };
  const auto list = [](const std::array<double, 4>& values) {
    std::ostringstream text;
    text << "[" << values[0] << ", " << values[1] << ", " << values[2] << ", " << values[3] << "]";
    return text.str();
  };
  if (p.delay_steps_max > 0)
  {
    item() << "delay ";
    if (p.delay_steps_max == p.delay_steps)
      out << p.delay_steps << (p.delay_steps == 1 ? " step (" : " steps (") << p.delay_steps * tau << " s)";
    else
      out << p.delay_steps << "-" << p.delay_steps_max << " steps (" << p.delay_steps * tau << "-"
          << p.delay_steps_max * tau << " s)";
  }
  if (p.noisy())
    item() << "noise_std " << list(p.noise_std) << " + noise_fraction " << list(p.noise_fraction);
  const std::pair<const char*, const ScaleRange*> ranges[] = {
      {"mass_cart", &p.mass_cart}, {"mass_pole", &p.mass_pole}, {"half_length", &p.half_length}, {"motor", &p.motor}};
  for (const auto& [name, range] : ranges)
  {
    if (range->varies())
      item() << name << " x[" << range->low << ", " << range->high << "]";
  }
  if (p.pushes())
    item() << "pushes of " << p.push_force << " N on " << p.push_probability << " of the steps";
  return out.tellp() > 0 ? out.str() : "none";
}

CartPoleState addSensorNoise(const CartPoleState& state, const PerturbationParams& p, RandomStream& rng)
{
  CartPoleState observed = state;
  for (int i = 0; i < 4; ++i)
  {
    // A draw for every noisy value, whatever the state: the stream stays aligned step by step.
    if (p.noise_std[i] != 0.0 || p.noise_fraction[i] != 0.0)
      observed[i] += (p.noise_std[i] + p.noise_fraction[i] * std::fabs(state[i])) * rng.normal();
  }
  return observed;
}

}  // namespace cartpole_qlearning
