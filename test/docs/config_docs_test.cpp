// docs/configuration.md's table of config/cartpole.yaml's keys checked against the sections' key
// tables (training_config.h's configKeys(), the tables that read and write them): a key added to a
// table without its row, or a row left for a key that is gone, fails here with the names.
#include "cartpole_qlearning/learning/training_config.h"

#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>

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

// The keys of the table under "## `config/cartpole.yaml`" (its rows up to the first line that is not one).
std::vector<std::string> documentedKeys(const std::string& page)
{
  std::istringstream in(page);
  std::string line;
  bool in_section = false;
  bool in_table = false;
  std::vector<std::string> keys;
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
      const std::string cell = line.substr(2, line.find(" |", 2) - 2);
      for (const std::string& key : rowKeys(cell))
        keys.push_back(key);
    }
  }
  return keys;
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
