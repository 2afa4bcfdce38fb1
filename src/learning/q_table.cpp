#include "cartpole_qlearning/learning/q_table.h"

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

QTable meanTable(const std::vector<QTable>& tables)
{
  if (tables.size() < 2)
    throw std::invalid_argument("a mean needs at least two tables, got " + std::to_string(tables.size()));
  const QTable& first = tables.front();
  std::vector<double> sum(first.values().size(), 0.0);
  std::uint64_t episodes = 0;
  std::uint64_t steps = 0;
  for (std::size_t i = 0; i < tables.size(); ++i)
  {
    const QTable& table = tables[i];
    const std::string which = "table " + std::to_string(i + 1) + " of " + std::to_string(tables.size());
    std::string differs = first.shapeMismatch(table);
    if (differs.empty() && table.tau != first.tau)
    {
      std::ostringstream out;
      out.precision(17);
      out << "its step (tau) " << table.tau << " s differs from table 1's " << first.tau << " s";
      differs = out.str();
    }
    if (differs.empty() && table.trained_with != first.trained_with)
      differs = "the configuration that trained it (trained_with) differs from table 1's";
    if (!differs.empty())
      throw std::invalid_argument(which + ": " + differs);
    for (std::size_t k = 0; k < sum.size(); ++k)
      sum[k] += table.values()[k];
    episodes += table.episodes;
    steps += table.steps;
  }
  const double count = static_cast<double>(tables.size());
  for (double& value : sum)
    value /= count;
  QTable mean = first;
  mean.setValues(std::move(sum));
  mean.episodes = episodes;
  mean.steps = steps;
  return mean;
}

}  // namespace cartpole_qlearning
