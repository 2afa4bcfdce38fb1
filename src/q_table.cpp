#include "cartpole_qlearning/q_table.h"

#include <sstream>
#include <stdexcept>

namespace cartpole_qlearning
{
QTable::QTable(const DiscretiserParams& discretiser, const std::vector<double>& actions)
  : discretiser_(discretiser), actions_(actions), state_count_(Discretiser(discretiser).stateCount())
{
  if (actions_.empty())
    throw std::invalid_argument("a Q-table needs at least one action");
  values_.assign(state_count_ * actions_.size(), 0.0);
}

std::size_t QTable::argmax(std::size_t state) const
{
  const double* row = &values_[state * actions_.size()];
  std::size_t best = 0;
  for (std::size_t a = 1; a < actions_.size(); ++a)
  {
    if (row[a] > row[best])
      best = a;
  }
  return best;
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

namespace
{
template <typename Container>
std::string listText(const Container& values)
{
  std::ostringstream out;
  out.precision(17);
  out << "[";
  bool first = true;
  for (const auto& v : values)
  {
    out << (first ? "" : ", ") << v;
    first = false;
  }
  out << "]";
  return out.str();
}
}  // namespace

std::string QTable::shapeMismatch(const QTable& other) const
{
  if (discretiser_.bins != other.discretiser_.bins)
    return "bins " + listText(other.discretiser_.bins) + " differ from " + listText(discretiser_.bins);
  if (!(discretiser_ == other.discretiser_))
    return "bin bounds lower " + listText(other.discretiser_.lower) + " upper " + listText(other.discretiser_.upper) +
           " differ from lower " + listText(discretiser_.lower) + " upper " + listText(discretiser_.upper);
  if (actions_ != other.actions_)
    return "actions " + listText(other.actions_) + " differ from " + listText(actions_);
  return "";
}

}  // namespace cartpole_qlearning
