// loadYaml (io/yaml_load.h): text that yaml-cpp before 0.7 never returns from is found, refused
// there before it parses, and every reader's refusal is what the user gets; other text, flow
// collections with colons included, loads as before.
#include "cartpole_qlearning/config/config_error.h"
#include "cartpole_qlearning/io/yaml_load.h"
#include "cartpole_qlearning/io/yaml_parameters.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

using cartpole_qlearning::flowColonOldYamlCppLoopsOn;
using cartpole_qlearning::loadYaml;
using cartpole_qlearning::loadYamlGuardsFlowColons;

namespace
{
// What the fuzzers found looping on Debian 11's yaml-cpp 0.6.3 ("[:", "{:", "q: [[:"), what the
// upstream reports name (jbeder/yaml-cpp#499, #899, #938), and the same inside a config.
const std::vector<std::string> kLooping = {
    "[:", "{:", "[:]", "{:]", "q: [[:", "{# ke\ny{:", "a: [b:]", "learning:\n  actions: [-10, 10:]\n", "[a, b:",
};
}  // namespace

TEST(YamlLoad, FindsEachColonThatOldYamlCppLoopsOn)
{
  for (const auto& text : kLooping)
    EXPECT_TRUE(flowColonOldYamlCppLoopsOn(text).has_value()) << text;
  const auto mark = flowColonOldYamlCppLoopsOn("learning:\n  actions: [-10, 10:]\n");
  ASSERT_TRUE(mark.has_value());
  EXPECT_EQ(1, mark->line);
  EXPECT_EQ(19, mark->column);
  EXPECT_EQ(29, mark->pos);
}

TEST(YamlLoad, LeavesOtherTextAlone)
{
  const std::vector<std::string> fine = {
      "{a: [1, 2]}",
      "[a:b]",
      "q: [1, 2]\nr:",
      "a:",
      "url: \"http://host:11311\"",
      "- [a, 'b:]']",
      "- [a, \"b\\\":]\"]",
      "# [a:]\nq: 1",
      "note: it's [here:x]",
      "times: {every: [0.5, 1.0], from: 0}\n",
      "",
  };
  for (const auto& text : fine)
  {
    EXPECT_FALSE(flowColonOldYamlCppLoopsOn(text).has_value()) << text;
    EXPECT_NO_THROW(loadYaml(text)) << text;
  }
  EXPECT_EQ(2u, loadYaml("{a: [1, 2]}")["a"].size());
}

TEST(YamlLoad, RefusesWhatOldYamlCppLoopsOnWithAParserException)
{
  for (const auto& text : kLooping)
  {
    try
    {
      loadYaml(text);
      // Only yaml-cpp 0.7 and later get here (they read "[:]", "a: [b:]" as one-pair mappings).
      EXPECT_FALSE(loadYamlGuardsFlowColons()) << text << ": loaded, with the guard on";
    }
    catch (const YAML::ParserException& e)
    {
      if (loadYamlGuardsFlowColons())
      {
        EXPECT_NE(std::string::npos, std::string(e.what()).find("yaml-cpp before 0.7")) << e.what();
        EXPECT_EQ(flowColonOldYamlCppLoopsOn(text)->pos, e.mark.pos) << text;
      }
    }
  }
  // Refused on every version: yaml-cpp 0.7 and later throw for these themselves.
  for (const std::string text : {"[:", "{:", "q: [[:", "{:]"})
    EXPECT_THROW(loadYaml(text), YAML::ParserException) << text;
  std::printf("this build's yaml-cpp %s refused first\n",
              loadYamlGuardsFlowColons() ? "is older than 0.7: such text is" : "is 0.7 or later: nothing is");
}

TEST(YamlLoad, AConfigOneTypoAwayIsAConfigErrorNamingTheFile)
{
  try
  {
    cartpole_qlearning::parseYamlParameters("learning:\n  alpha: 0.1\n  actions: [-10, 10:", "my.yaml");
    FAIL() << "accepted";
  }
  catch (const cartpole_qlearning::ConfigError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("my.yaml: not valid YAML")) << e.what();
  }
}
