// docs/nodes.md checked against the code: each node's Parameters section lists every private
// parameter the node reads, and none that it does not. The settings readers are run on a source
// that records every key asked for; the ROS layer's own reads (pnh_.getParam) are found in its
// source. A parameter added to a reader without its line on the page, or a line left for one that
// is gone, fails here with the names.
#include "cartpole_qlearning/node_settings/controller_settings.h"
#include "cartpole_qlearning/node_settings/sim_settings.h"

#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace cartpole_qlearning;
using cartpole_qlearning::test::fileText;
namespace text_match = cartpole_qlearning::test::text_match;

namespace
{
// Answers from an inner source and notes every key asked for.
class RecordingSource : public ParameterSource
{
public:
  RecordingSource(std::unique_ptr<ParameterSource> inner, std::set<std::string>& asked)
    : inner_(std::move(inner)), asked_(asked)
  {
  }
  bool get(const std::string& key, double& value) const override
  {
    return note(key) && inner_->get(key, value);
  }
  bool get(const std::string& key, std::int64_t& value) const override
  {
    return note(key) && inner_->get(key, value);
  }
  bool get(const std::string& key, bool& value) const override
  {
    return note(key) && inner_->get(key, value);
  }
  bool get(const std::string& key, std::string& value) const override
  {
    return note(key) && inner_->get(key, value);
  }
  bool get(const std::string& key, std::vector<double>& value) const override
  {
    return note(key) && inner_->get(key, value);
  }
  bool get(const std::string& key, std::vector<std::string>& value) const override
  {
    return note(key) && inner_->get(key, value);
  }
  std::vector<std::string> keysUnder(const std::string& section) const override
  {
    return inner_->keysUnder(section);
  }
  std::string origin() const override
  {
    return inner_->origin();
  }

private:
  bool note(const std::string& key) const
  {
    asked_.insert(key);
    return true;
  }
  std::unique_ptr<ParameterSource> inner_;
  std::set<std::string>& asked_;
};

// The private keys a ROS-layer source reads itself: pnh_.getParam("KEY", ...) and pnh_.param("KEY", ...).
std::set<std::string> rosLayerReads(const std::string& source_file)
{
  const std::string text = fileText(std::string(CARTPOLE_SOURCE_DIR) + "/" + source_file);
  EXPECT_FALSE(text.empty()) << source_file;
  std::set<std::string> keys;
  for (const text_match::Groups& read : text_match::allMatches(text, R"(pnh_\.(?:getParam|param)\s*\(\s*"([^"]+)\")"))
    keys.insert(read[1]);
  return keys;
}

// The names of `- \`~name\`` lines in the "### Parameters" section under "## <node>" of the page.
std::set<std::string> documentedParameters(const std::string& page, const std::string& node)
{
  std::istringstream in(page);
  std::set<std::string> names;
  std::string line;
  bool in_node = false;
  bool in_parameters = false;
  const std::string item = R"(^- `~([A-Za-z0-9_/]+)` \()";
  while (std::getline(in, line))
  {
    if (line.rfind("## ", 0) == 0)
      in_node = line == "## " + node;
    if (line.rfind("### ", 0) == 0 || line.rfind("## ", 0) == 0)
      in_parameters = in_node && line == "### Parameters";
    text_match::Groups match;
    if (in_parameters && text_match::contains(line, item, &match))
      names.insert(match[1]);
  }
  return names;
}

std::string listed(const std::set<std::string>& names)
{
  std::string text;
  for (const std::string& name : names)
    text += (text.empty() ? "~" : ", ~") + name;
  return text.empty() ? "none" : text;
}

// Both ways, with the names that differ in the message.
void expectSameNames(const std::set<std::string>& read, const std::set<std::string>& documented,
                     const std::string& node)
{
  std::set<std::string> missing;
  std::set<std::string> extra;
  for (const std::string& name : read)
    if (!documented.count(name))
      missing.insert(name);
  for (const std::string& name : documented)
    if (!read.count(name))
      extra.insert(name);
  EXPECT_TRUE(missing.empty()) << "docs/nodes.md, " << node << ", ### Parameters: " << node << " reads "
                               << listed(missing) << ", not listed there (add a line `- `~name` (type, default): ...`)";
  EXPECT_TRUE(extra.empty()) << "docs/nodes.md, " << node << ", ### Parameters: lists " << listed(extra) << ", which "
                             << node << " does not read";
}

std::string page()
{
  return fileText(std::string(CARTPOLE_SOURCE_DIR) + "/docs/nodes.md");
}
}  // namespace

TEST(NodeDocsTest, TheSimsParametersAreTheOnesItReads)
{
  std::set<std::string> read;
  // Each mode, in case a key is read in one only.
  for (const std::string priv : {"", "mode: lockstep\npublish_clock: true\n"})
  {
    RecordingSource source(parseYamlParameters(priv, "/cartpole/cartpole_sim"), read);
    readSimSettings(*parseYamlParameters("", "/cartpole"), source);
  }
  for (const std::string& key : rosLayerReads("src/ros/cartpole_sim.cpp"))
    read.insert(key);
  ASSERT_GT(read.size(), 10u) << "the recording source saw too little: " << listed(read);
  const std::string text = page();
  ASSERT_FALSE(text.empty()) << "no docs/nodes.md";
  expectSameNames(read, documentedParameters(text, "cartpole_sim"), "cartpole_sim");
}

TEST(NodeDocsTest, TheControllersParametersAreTheOnesItReads)
{
  std::set<std::string> read;
  ControllerContext context;
  for (const std::string priv : {"", "mode: evaluate\n", "robots: 3\nreset_service: ''\n"})
  {
    RecordingSource source(parseYamlParameters(priv, "/cartpole/qlearning_controller"), read);
    readControllerSettings(*parseYamlParameters("", "/cartpole"), source, context);
  }
  for (const std::string& key : rosLayerReads("src/ros/qlearning_controller.cpp"))
    read.insert(key);
  ASSERT_TRUE(read.count("run/id")) << "the ROS layer's own reads were not found: " << listed(read);
  ASSERT_GT(read.size(), 20u) << "the recording source saw too little: " << listed(read);
  const std::string text = page();
  ASSERT_FALSE(text.empty()) << "no docs/nodes.md";
  expectSameNames(read, documentedParameters(text, "qlearning_controller"), "qlearning_controller");
}

TEST(NodeDocsTest, ThePagesParametersAreFoundWhereTheyAre)
{
  // The parser itself: only the node's own Parameters section counts.
  const std::string text =
      "## a\n### Parameters\n- `~one` (int, 0): x.\n- `~two/sub` (string, \"\"): y.\n"
      "### Dynamic reconfigure\n- `~not_this` (double, 1): z.\n## b\n### Parameters\n"
      "- `~other` (bool, true): w.\n";
  EXPECT_EQ((std::set<std::string>{"one", "two/sub"}), documentedParameters(text, "a"));
  EXPECT_EQ((std::set<std::string>{"other"}), documentedParameters(text, "b"));
}
