// A section's table of keys drives its reading (checks and unknown keys included) and its writing,
// whatever holds the values: here a map in memory, the config layer having no file format.
#include "cartpole_qlearning/config/config_section.h"

#include <gtest/gtest.h>

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

using namespace cartpole_qlearning;

namespace
{
// Numbers and texts by key; a text asked for as a number is the wrong type.
class MapSource : public ParameterSource
{
public:
  explicit MapSource(std::map<std::string, std::string> values) : values_(std::move(values)) {}
  bool get(const std::string& key, double& value) const override
  {
    const auto found = values_.find(key);
    if (found == values_.end())
      return false;
    try
    {
      value = std::stod(found->second);
    }
    catch (const std::invalid_argument&)
    {
      throw ConfigError(origin() + ": " + key + " = '" + found->second + "' is not allowed (must be a number)");
    }
    return true;
  }
  bool get(const std::string& key, std::int64_t& value) const override
  {
    double number = 0.0;
    if (!get(key, number))
      return false;
    value = static_cast<std::int64_t>(number);
    return true;
  }
  bool get(const std::string&, bool&) const override
  {
    return false;
  }
  bool get(const std::string& key, std::string& value) const override
  {
    const auto found = values_.find(key);
    if (found == values_.end())
      return false;
    value = found->second;
    return true;
  }
  bool get(const std::string&, std::vector<double>&) const override
  {
    return false;
  }
  bool get(const std::string&, std::vector<std::string>&) const override
  {
    return false;
  }
  std::vector<std::string> keysUnder(const std::string& section) const override
  {
    std::vector<std::string> keys;
    for (const auto& entry : values_)
      if (entry.first.rfind(section + "/", 0) == 0 || entry.first == section)
        keys.push_back(entry.first);
    return keys;
  }
  std::string origin() const override
  {
    return "test.yaml";
  }

private:
  std::map<std::string, std::string> values_;
};

// What was written, one "key=value" a line.
class TextSink : public ParameterSink
{
public:
  void number(const std::string& key, double value) override
  {
    add(key, std::to_string(value));
  }
  void whole(const std::string& key, std::uint64_t value) override
  {
    add(key, std::to_string(value));
  }
  void flag(const std::string& key, bool value) override
  {
    add(key, value ? "true" : "false");
  }
  void word(const std::string& key, const std::string& value) override
  {
    add(key, value);
  }
  void text(const std::string& key, const std::string& value) override
  {
    add(key, "\"" + value + "\"");
  }
  void numbers(const std::string& key, const std::vector<double>& values) override
  {
    add(key, std::to_string(values.size()) + " numbers");
  }
  void texts(const std::string& key, const std::vector<std::string>& values) override
  {
    add(key, std::to_string(values.size()) + " texts");
  }
  std::string written;

private:
  void add(const std::string& key, const std::string& value)
  {
    written += key + "=" + value + "\n";
  }
};

struct Params
{
  double rate = 0.5;
  unsigned steps = 10;
  std::string label = "a";
};

const ConfigSection<Params>& section()
{
  static const ConfigSection<Params> s{
      "demo",
      {plainKey<Params>(
           "rate", "double: how fast", [](auto& p) -> auto& { return p.rate; }),
       wholeKey<Params>(
           "steps", "int: how many", [](auto& p) -> auto& { return p.steps; }, 1, 100),
       plainKey<Params>(
           "label", "string: a name", [](auto& p) -> auto& { return p.label; })},
      [](const SectionReader& reader, const Params& p) {
        if (p.rate > 1.0)
          reader.check("rate = " + SectionReader::numberText(p.rate) + " is not allowed (must be <= 1)");
      }};
  return s;
}

std::string readError(const std::map<std::string, std::string>& values)
{
  Params p;
  try
  {
    section().read(MapSource(values), p);
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ConfigSectionTest, ReadsTheKeysGivenOverTheDefaults)
{
  Params p;
  section().read(MapSource({{"demo/steps", "20"}, {"demo/label", "b"}}), p);
  EXPECT_EQ(0.5, p.rate);
  EXPECT_EQ(20u, p.steps);
  EXPECT_EQ("b", p.label);
}

TEST(ConfigSectionTest, RefusesAnUnknownKeyListingTheTablesKeys)
{
  EXPECT_EQ("test.yaml: unknown key demo/rat (known keys of demo: label, rate, steps)",
            readError({{"demo/rat", "0.1"}}));
  EXPECT_EQ("", readError({{"other/rat", "0.1"}})) << "another section's keys are not this one's to refuse";
}

TEST(ConfigSectionTest, RefusesABadValueNamingTheKey)
{
  EXPECT_EQ("test.yaml: demo/steps = 0 is not allowed (must be a whole number in [1, 100])",
            readError({{"demo/steps", "0"}}));
  EXPECT_EQ("test.yaml: demo/rate = 'x' is not allowed (must be a number)", readError({{"demo/rate", "x"}}));
  EXPECT_EQ("test.yaml: demo/rate = 2 is not allowed (must be <= 1)", readError({{"demo/rate", "2"}}));
}

TEST(ConfigSectionTest, WritesEveryKeyInTheTablesOrder)
{
  TextSink sink;
  section().write(sink, Params());
  EXPECT_EQ("demo/rate=0.500000\ndemo/steps=10\ndemo/label=\"a\"\n", sink.written);
  EXPECT_EQ((std::vector<std::string>{"demo/rate", "demo/steps", "demo/label"}), section().keyNames());
}
