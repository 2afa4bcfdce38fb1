// Reads the keys of one section of a ParameterSource, remembers which keys it knows, and refuses the
// others, so that a misspelt key stops the run instead of being silently ignored. Each read names the
// key, the value and what is allowed when it refuses one.
#pragma once

#include "cartpole_qlearning/config/parameter_source.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
class SectionReader
{
public:
  SectionReader(const ParameterSource& source, std::string section) : source_(source), section_(std::move(section)) {}

  template <typename T>
  void read(const std::string& name, T& value)
  {
    known_.insert(key(name));
    source_.get(key(name), value);
  }

  void read(const std::string& name, unsigned& value, std::int64_t min, std::int64_t max);
  void read(const std::string& name, std::uint64_t& value, std::int64_t min);
  // A finite number, > min (strict) or >= min.
  void readAtLeast(const std::string& name, double& value, double min, bool strict);
  // A duration in seconds in [min, max] ((min, max] when strict): the message names the unit, so
  // that milliseconds typed as seconds (decision_period: 20) read as what they are.
  void readSeconds(const std::string& name, double& value, double min, double max, bool strict);
  // One of the allowed strings.
  void readChoice(const std::string& name, std::string& value, const std::vector<std::string>& allowed);

  // A list of exactly N numbers, `entries` naming them for the message ("x, x_dot, theta, theta_dot");
  // whole_max > 0: whole numbers in [1, whole_max].
  template <typename T, std::size_t N>
  void readList(const std::string& name, std::array<T, N>& values, const std::string& entries,
                std::int64_t whole_max = 0)
  {
    std::vector<double> list;
    known_.insert(key(name));
    if (!source_.get(key(name), list))
      return;
    if (list.size() != N)
      fail(name, listText(list), "must list " + std::to_string(N) + " values: " + entries);
    for (std::size_t i = 0; i < N; ++i)
    {
      // Checked before the conversion: a value out of the type's range would be undefined.
      if (whole_max > 0 && (list[i] != std::floor(list[i]) || list[i] < 1 || list[i] > double(whole_max)))
        fail(name, listText(list), "must be whole numbers in [1, " + std::to_string(whole_max) + "]");
      values[i] = static_cast<T>(list[i]);
    }
  }

  // A key read by other means (a value of a form the sources do not offer): not unknown.
  void know(const std::string& name)
  {
    known_.insert(key(name));
  }
  // Whether the source sets the key (or keys below it).
  bool has(const std::string& name) const
  {
    return !source_.keysUnder(key(name)).empty();
  }
  const ParameterSource& source() const
  {
    return source_;
  }

  // Refuses a key under this section that no read() asked for.
  void refuseUnknown() const;
  // Turns a validate() message, which names the field relative to this section, into a ConfigError.
  void check(const std::string& error) const;
  [[noreturn]] void fail(const std::string& name, const std::string& value, const std::string& allowed) const;

  // The key of a name in this section ("learning" + "gamma" -> "learning/gamma"; no section: the name).
  std::string key(const std::string& name) const
  {
    return section_.empty() ? name : section_ + "/" + name;
  }

  static std::string numberText(double value);
  static std::string listText(const std::vector<double>& list);

private:
  std::string knownText() const;

  const ParameterSource& source_;
  std::string section_;
  std::set<std::string> known_;
};

}  // namespace cartpole_qlearning
