#include "cartpole_qlearning/config/section_reader.h"

#include <algorithm>
#include <sstream>

namespace cartpole_qlearning
{
void SectionReader::read(const std::string& name, unsigned& value, std::int64_t min, std::int64_t max)
{
  std::int64_t v = value;
  read(name, v);
  if (v < min || v > max)
    fail(name, std::to_string(v),
         "must be a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  value = static_cast<unsigned>(v);
}

void SectionReader::read(const std::string& name, std::uint64_t& value, std::int64_t min)
{
  std::int64_t v = static_cast<std::int64_t>(value);
  read(name, v);
  if (v < min)
    fail(name, std::to_string(v), "must be a whole number >= " + std::to_string(min));
  value = static_cast<std::uint64_t>(v);
}

void SectionReader::readAtLeast(const std::string& name, double& value, double min, bool strict)
{
  read(name, value);
  if (!(std::isfinite(value) && (strict ? value > min : value >= min)))
    fail(name, numberText(value), std::string("must be finite and ") + (strict ? "> " : ">= ") + numberText(min));
}

void SectionReader::readSeconds(const std::string& name, double& value, double min, double max, bool strict)
{
  read(name, value);
  if (!(std::isfinite(value) && (strict ? value > min : value >= min) && value <= max))
    fail(name, numberText(value),
         std::string("must be in ") + (strict ? "(" : "[") + numberText(min) + ", " + numberText(max) +
             "] seconds (20 ms is 0.02)");
}

void SectionReader::readChoice(const std::string& name, std::string& value, const std::vector<std::string>& allowed)
{
  read(name, value);
  if (std::find(allowed.begin(), allowed.end(), value) != allowed.end())
    return;
  std::string list;
  for (const std::string& a : allowed)
    list += (list.empty() ? "" : ", ") + a;
  fail(name, "'" + value + "'", "allowed: " + list);
}

void SectionReader::refuseUnknown() const
{
  for (const std::string& k : source_.keysUnder(section_))
  {
    if (known_.count(k) == 0)
      throw ConfigError(source_.origin() + ": unknown key " + k + " (known keys" +
                        (section_.empty() ? std::string() : " of " + section_) + ": " + knownText() + ")");
  }
}

void SectionReader::check(const std::string& error) const
{
  if (!error.empty())
    throw ConfigError(source_.origin() + ": " + section_ + "/" + error);
}

void SectionReader::fail(const std::string& name, const std::string& value, const std::string& allowed) const
{
  throw ConfigError(source_.describe(key(name)) + " = " + value + " is not allowed (" + allowed + ")");
}

std::string SectionReader::numberText(double value)
{
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string SectionReader::listText(const std::vector<double>& list)
{
  std::ostringstream out;
  out << "[";
  for (std::size_t i = 0; i < list.size(); ++i)
    out << (i ? ", " : "") << list[i];
  out << "]";
  return out.str();
}

std::string SectionReader::knownText() const
{
  std::string text;
  for (const std::string& k : known_)
    text += (text.empty() ? "" : ", ") + k.substr(section_.empty() ? 0 : section_.size() + 1);
  return text;
}

}  // namespace cartpole_qlearning
