// docs/configuration.md's table of config/cartpole.yaml's keys checked against the sections' key
// tables (training_config.h's configKeys(), the tables that read and write them): a key added to a
// table without its row, or a row left for a key that is gone, fails here with the names; and each
// default the page gives as a value is the one the tables write for a default configuration.
#include "cartpole_qlearning/learning/training_config.h"

#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace cartpole_qlearning;
using cartpole_qlearning::test::fileText;
namespace text_match = cartpole_qlearning::test::text_match;

namespace
{
// The keys a row's first cell names: "`physics/cart_joint`, `pole_joint`" is physics/cart_joint and
// physics/pole_joint (a name without a slash is the first one's sibling); "`learning/alpha/...`"
// stands for every key under learning/alpha/ (kept as "learning/alpha/...").
std::vector<std::string> rowKeys(const std::string& cell)
{
  std::vector<std::string> keys;
  std::string parent;
  for (const text_match::Groups& quoted : text_match::allMatches(cell, "`([^`]+)`"))
  {
    const std::string& name = quoted[1];
    if (name.find('/') == std::string::npos && !parent.empty())
      keys.push_back(parent + name);
    else
    {
      keys.push_back(name);
      parent = name.substr(0, name.rfind('/') + 1);
    }
  }
  return keys;
}

struct Row
{
  std::vector<std::string> keys;
  std::string default_cell;
};

// The rows of the table under "## `config/cartpole.yaml`" (up to the first line that is not one).
std::vector<Row> documentedRows(const std::string& page)
{
  std::istringstream in(page);
  std::string line;
  bool in_section = false;
  bool in_table = false;
  std::vector<Row> rows;
  while (std::getline(in, line))
  {
    if (line.rfind("## ", 0) == 0)
      in_section = line == "## `config/cartpole.yaml`";
    if (!in_section)
      continue;
    if (line.rfind("| key |", 0) == 0)
      in_table = true;
    else if (in_table && line.rfind("| `", 0) != 0 && line.rfind("| ---", 0) != 0)
      break;
    else if (in_table && line.rfind("| `", 0) == 0)
    {
      std::vector<std::string> cells;
      std::size_t at = 1;
      for (std::size_t bar = line.find(" |", at); bar != std::string::npos; bar = line.find(" |", at))
      {
        cells.push_back(line.substr(at + 1, bar - at - 1));
        at = bar + 2;
      }
      if (!cells.empty())
        rows.push_back({rowKeys(cells[0]), cells.size() >= 3 ? cells[2] : ""});
    }
  }
  return rows;
}

std::vector<std::string> documentedKeys(const std::string& page)
{
  std::vector<std::string> keys;
  for (const Row& row : documentedRows(page))
    keys.insert(keys.end(), row.keys.begin(), row.keys.end());
  return keys;
}

// What the tables write, key by key, as the page would show it (lists "[a, b]").
class CaptureSink : public ParameterSink
{
public:
  void number(const std::string& key, double value) override
  {
    written[key] = exactText(value);
  }
  void whole(const std::string& key, std::uint64_t value) override
  {
    written[key] = std::to_string(value);
  }
  void flag(const std::string& key, bool value) override
  {
    written[key] = value ? "true" : "false";
  }
  void word(const std::string& key, const std::string& value) override
  {
    written[key] = value;
  }
  void text(const std::string& key, const std::string& value) override
  {
    written[key] = value;
  }
  void numbers(const std::string& key, const std::vector<double>& values) override
  {
    std::string text;
    for (const double value : values)
      text += (text.empty() ? "" : ", ") + exactText(value);
    written[key] = "[" + text + "]";
  }
  void texts(const std::string&, const std::vector<std::string>&) override {}
  std::map<std::string, std::string> written;
};

std::map<std::string, std::string> defaultsWritten()
{
  const TrainingConfig config;
  CaptureSink sink;
  physicsSection().write(sink, PhysicsSection{config.physics, config.engine, config.start_state_bound});
  perturbationsSection().write(sink, config.perturbations);
  taskSection().write(sink, config.task);
  learningSection().write(sink, config.agent);
  trainingSection().write(sink, config.limits);
  return sink.written;
}

// A value as numbers ("2.4", "[1, 1, 6, 12]", "−10" with the page's minus sign); false: not numbers.
bool numbersOf(std::string text, std::vector<double>& numbers)
{
  for (std::size_t at = text.find("\u2212"); at != std::string::npos; at = text.find("\u2212"))
    text.replace(at, std::string("\u2212").size(), "-");
  if (!text.empty() && text.front() == '[' && text.back() == ']')
    text = text.substr(1, text.size() - 2);
  numbers.clear();
  std::istringstream in(text);
  std::string part;
  while (std::getline(in, part, ','))
  {
    std::size_t used = 0;
    try
    {
      numbers.push_back(std::stod(part, &used));
    }
    catch (const std::exception&)
    {
      return false;
    }
    if (part.find_first_not_of(' ', used) != std::string::npos)
      return false;
  }
  return !numbers.empty();
}

// The default cell's values, one per key of the row ("1.0, 0.03" for two keys; one value for all).
// Empty when the cell says it in words ("(none)", "zeros", "`task/reward`'s").
std::vector<std::string> cellValues(const std::string& cell, std::size_t keys)
{
  std::string plain;
  for (const char c : cell)
    if (c != '`')
      plain += c;
  std::vector<std::string> values;
  std::vector<double> numbers;
  if (plain.empty() || keys == 0)
    return values;
  if (keys == 1 || (plain.front() == '[' && numbersOf(plain, numbers)))
    values.assign(keys, plain);
  else
  {
    std::istringstream in(plain);
    std::string part;
    while (std::getline(in, part, ','))
      values.push_back(part.substr(part.find_first_not_of(' ')));
  }
  for (const std::string& value : values)
    if (!numbersOf(value, numbers) && !text_match::matchesWhole(value, "[a-z0-9_.]+"))
      return {};
  return values.size() == keys ? values : std::vector<std::string>{};
}

bool covers(const std::string& documented, const std::string& key)
{
  const std::string any = "/...";
  if (documented.size() > any.size() && documented.compare(documented.size() - any.size(), any.size(), any) == 0)
    return key.compare(0, documented.size() - 3, documented, 0, documented.size() - 3) == 0;
  return documented == key;
}
}  // namespace

TEST(ConfigDocsTest, TheRowsNameTheKeysTheyList)
{
  EXPECT_EQ((std::vector<std::string>{"physics/cart_joint", "physics/pole_joint", "physics/actuator"}),
            rowKeys("`physics/cart_joint`, `pole_joint`, `actuator`"));
  EXPECT_EQ((std::vector<std::string>{"learning/epsilon/start", "learning/epsilon/min"}),
            rowKeys("`learning/epsilon/start`, `min`"));
  EXPECT_TRUE(covers("learning/alpha/...", "learning/alpha/min"));
  EXPECT_FALSE(covers("learning/alpha/...", "learning/epsilon/min"));
  EXPECT_FALSE(covers("task/x_cost", "task/x_dot_cost"));
  const std::string page =
      "## `config/cartpole.yaml`\n\n| key | type |\n| --- | --- |\n| `task/reward` | string |\n"
      "| `task/x_cost`, `x_dot_cost` | double |\n\nThe end.\n| `not/this` | x |\n";
  EXPECT_EQ((std::vector<std::string>{"task/reward", "task/x_cost", "task/x_dot_cost"}), documentedKeys(page));
}

TEST(ConfigDocsTest, ThePageListsEveryKeyOfTheSectionsTablesAndNoOther)
{
  const std::string page = fileText(std::string(CARTPOLE_SOURCE_DIR) + "/docs/configuration.md");
  ASSERT_FALSE(page.empty()) << "no docs/configuration.md";
  const std::vector<std::string> documented = documentedKeys(page);
  const std::vector<std::string> keys = configKeys();
  ASSERT_GT(documented.size(), 30u) << "the table of docs/configuration.md was not found";
  ASSERT_GT(keys.size(), 50u);
  for (const std::string& key : keys)
  {
    bool found = false;
    for (const std::string& name : documented)
      found = found || covers(name, key);
    EXPECT_TRUE(found) << key << " is read and written (its section's table) but not in docs/configuration.md's "
                       << "table of config/cartpole.yaml (add its row: key, type, default, allowed)";
  }
  for (const std::string& name : documented)
  {
    bool found = false;
    for (const std::string& key : keys)
      found = found || covers(name, key);
    EXPECT_TRUE(found) << name << " is in docs/configuration.md's table but in no section's table of keys";
  }
}

TEST(ConfigDocsTest, TheDefaultsOnThePageAreTheTablesOwn)
{
  const std::string page = fileText(std::string(CARTPOLE_SOURCE_DIR) + "/docs/configuration.md");
  const std::map<std::string, std::string> written = defaultsWritten();
  const std::vector<std::string> keys = configKeys();
  std::size_t compared = 0;
  for (const Row& row : documentedRows(page))
  {
    // "learning/alpha/..." stands for the section's keys under it, in the table's order.
    std::vector<std::string> row_keys;
    for (const std::string& name : row.keys)
      for (const std::string& key : keys)
        if (covers(name, key))
          row_keys.push_back(key);
    const std::vector<std::string> values = cellValues(row.default_cell, row_keys.size());
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      const auto found = written.find(row_keys[i]);
      if (found == written.end())
        continue;  // not written by default (another engine's key, a key that says nothing unless set)
      std::vector<double> page_numbers;
      std::vector<double> own_numbers;
      if (numbersOf(values[i], page_numbers) && numbersOf(found->second, own_numbers))
        EXPECT_EQ(own_numbers, page_numbers)
            << row_keys[i] << ": docs/configuration.md says " << values[i] << ", the default is " << found->second;
      else
        EXPECT_EQ(found->second, values[i]) << row_keys[i] << ": docs/configuration.md's default";
      ++compared;
    }
  }
  EXPECT_GT(compared, 40u) << "too few defaults compared (" << compared << "): the page's table was not read";
}
