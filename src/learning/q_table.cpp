#include "cartpole_qlearning/learning/q_table.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
namespace
{
FeatureParams binsOf(const DiscretiserParams& discretiser)
{
  FeatureParams features;
  features.discretiser = discretiser;
  return features;
}
}  // namespace

std::uint64_t maxQTableFileBytes(std::uint64_t rows, std::uint64_t actions)
{
  constexpr std::uint64_t kHeaderBytes = std::uint64_t(1) << 20;
  constexpr std::uint64_t kRowBytes = 8;     // "  - [" and "]\n"
  constexpr std::uint64_t kValueBytes = 26;  // "-2.2250738585072014e-308, "
  return kHeaderBytes + 2 * rows * (kRowBytes + kValueBytes * actions);
}

QTable::QTable(const DiscretiserParams& discretiser, const std::vector<double>& actions)
  : QTable(binsOf(discretiser), actions)
{
}

QTable::QTable(const FeatureParams& features, const std::vector<double>& actions)
  : features_(features), actions_(actions), state_count_(FeatureMap(features, actions.size()).rowCount())
{
  if (actions_.empty())
    throw std::invalid_argument("a Q-table needs at least one action");
  values_.assign(state_count_ * actions_.size(), 0.0);
}

double QTable::max(std::size_t state) const
{
  return at(state, argmax(state));
}

void QTable::setValues(std::vector<double> values)
{
  if (values.size() != values_.size())
  {
    std::ostringstream out;
    out << "expected " << values_.size() << " values (" << state_count_ << " states x " << actions_.size()
        << " actions), got " << values.size();
    throw std::invalid_argument(out.str());
  }
  values_ = std::move(values);
}

std::string QTable::shapeMismatch(const QTable& other) const
{
  return tableShapeMismatch(features_, actions_, other);
}

std::string tableShapeMismatch(const FeatureParams& features, const std::vector<double>& actions, const QTable& other)
{
  const std::string differs = features.mismatch(other.features());
  if (!differs.empty())
    return differs;
  if (actions != other.actions())
  {
    std::ostringstream out;
    out.precision(17);
    const auto list = [&out](const std::vector<double>& values) {
      out << "[";
      for (std::size_t i = 0; i < values.size(); ++i)
        out << (i ? ", " : "") << values[i];
      out << "]";
    };
    out << "actions ";
    list(other.actions());
    out << " differ from ";
    list(actions);
    return out.str();
  }
  return "";
}

TableMean::TableMean(QTable first) : sum_(std::move(first)) {}

namespace
{
// The first line where two texts differ, as "LINE (the first: OTHER)".
std::string firstDifferingLine(const std::string& text, const std::string& first)
{
  std::istringstream a(text);
  std::istringstream b(first);
  std::string line_a;
  std::string line_b;
  for (int number = 1;; ++number)
  {
    const bool more_a = static_cast<bool>(std::getline(a, line_a));
    const bool more_b = static_cast<bool>(std::getline(b, line_b));
    if (!more_a && !more_b)
      return "";
    if (!more_a || !more_b || line_a != line_b)
      return "line " + std::to_string(number) + " '" + (more_a ? line_a : "(none)") + "' where the first's is '" +
             (more_b ? line_b : "(none)") + "'";
  }
}
}  // namespace

void TableMean::add(const QTable& table)
{
  std::string differs = sum_.shapeMismatch(table);
  if (differs.empty() && table.tau != sum_.tau)
  {
    std::ostringstream out;
    out.precision(17);
    out << "its step (tau) " << table.tau << " s differs from the first table's " << sum_.tau << " s";
    differs = out.str();
  }
  if (differs.empty() && table.trained_with != sum_.trained_with)
    differs = "the configuration that trained it (trained_with) differs from the first table's at " +
              firstDifferingLine(table.trained_with, sum_.trained_with);
  if (!differs.empty())
    throw std::invalid_argument(differs);
  // In place: a table may hold 160 MB.
  for (std::size_t state = 0; state < sum_.stateCount(); ++state)
    for (std::size_t action = 0; action < sum_.actionCount(); ++action)
      sum_.at(state, action) += table.at(state, action);
  counters_overflow_ =
      counters_overflow_ || sum_.episodes + table.episodes < sum_.episodes || sum_.steps + table.steps < sum_.steps;
  sum_.episodes += table.episodes;
  sum_.steps += table.steps;
  ++count_;
}

QTable TableMean::mean() const
{
  if (counters_overflow_)
    throw std::invalid_argument("the tables' episode or step counts sum past the largest count a table holds");
  const double count = static_cast<double>(count_);
  QTable mean = sum_;
  for (std::size_t state = 0; state < mean.stateCount(); ++state)
    for (std::size_t action = 0; action < mean.actionCount(); ++action)
    {
      double& value = mean.at(state, action);
      if (!std::isfinite(value))
        throw std::invalid_argument("a value's sum over the tables is not finite (values near the largest double)");
      value /= count;
    }
  return mean;
}

}  // namespace cartpole_qlearning
