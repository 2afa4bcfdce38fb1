// The core's layers (src/<layer>/, include/cartpole_qlearning/<layer>/) build without ROS: a core
// file may include the standard library, POSIX, Eigen, yaml-cpp and the headers of its own layer
// and of the layers below it, and nothing else. Debian installs the ROS headers on the default
// include path, so a stray #include <ros/ros.h> would still compile; this test is what stops it.
// (The link lines stop a call into a layer above: each layer is a library linked with
// -Wl,--no-undefined against the ones below. A header-only use would pass them: this test does not.)
#include "text_match.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace
{
namespace fs = std::filesystem;
namespace text_match = cartpole_qlearning::test::text_match;

const fs::path kSource = CARTPOLE_SOURCE_DIR;

// From the bottom (CMakeLists.txt's CORE_LAYERS): a layer may include its own and those before it.
const std::vector<std::string> kLayers = {"common",   "config",   "io",         "simulation",
                                          "learning", "protocol", "application"};

std::size_t layerRank(const std::string& layer)
{
  return static_cast<std::size_t>(std::find(kLayers.begin(), kLayers.end(), layer) - kLayers.begin());
}

// The #include lines of a file's text that the core may not have, as "line N: #include ...".
// core_header(name) tells whether "cartpole_qlearning/name" is a core header.
template <typename CoreHeader>
std::vector<std::string> foreignIncludes(const std::string& text, CoreHeader core_header)
{
  // <vector>, <cstdint>; <unistd.h>, <sys/stat.h>; <Eigen/Core>; <yaml-cpp/yaml.h>
  static const std::string allowed_system =
      R"(<([a-z_]+|[a-z_]+\.h|sys/[a-z_]+\.h|Eigen/[A-Za-z]+|yaml-cpp/[a-z_/]+\.h)>)";
  static const std::string include = R"re(^\s*#\s*include\s*([<"][^>"]*[>"]))re";
  static const std::string own = R"re("cartpole_qlearning/([a-z0-9_]+/[a-z0-9_]+\.h)")re";
  std::vector<std::string> foreign;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number)
  {
    text_match::Groups m;
    if (!text_match::contains(line, include, &m))
      continue;
    const std::string target = m[1];
    text_match::Groups o;
    const bool ok = text_match::matchesWhole(target, allowed_system) ||
                    (text_match::matchesWhole(target, own, &o) && core_header(o[1]));
    if (!ok)
      foreign.push_back("line " + std::to_string(number) + ": " + line);
  }
  return foreign;
}

// Whether "cartpole_qlearning/<layer>/<file>.h" is a header of the core in a layer a file of
// `layer` may include (its own or one below).
bool isHeaderAtOrBelow(const std::string& layer, const std::string& name)
{
  const std::string header_layer = name.substr(0, name.find('/'));
  return layerRank(header_layer) <= layerRank(layer) && layerRank(header_layer) < kLayers.size() &&
         fs::is_regular_file(kSource / "include" / "cartpole_qlearning" / name);
}

std::string readText(const fs::path& path)
{
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The text without its includes of private headers beside it in its folder (#include "name.h",
// a file of `folder`): a folder's own, as a layer's private headers in src/<layer>/ are.
std::string withoutFolderIncludes(const std::string& text, const fs::path& folder)
{
  std::string kept;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
  {
    text_match::Groups m;
    const bool own = text_match::contains(line, R"re(^\s*#\s*include\s*"([a-z0-9_]+\.h)")re", &m) &&
                     fs::is_regular_file(folder / m[1]);
    kept += (own ? "" : line) + "\n";
  }
  return kept;
}

TEST(CoreLayoutTest, TheCheckRefusesRosHeadersAndGeneratedMessages)
{
  const auto core = [](const std::string& name) { return name == "learning/q_table.h"; };
  EXPECT_TRUE(
      foreignIncludes("#include <vector>\n#include <Eigen/Core>\n#include \"cartpole_qlearning/learning/q_table.h\"\n"
                      "#include <sys/stat.h>\n#include <yaml-cpp/yaml.h>\n",
                      core)
          .empty());
  EXPECT_EQ(foreignIncludes("#include <vector>\n#include <ros/ros.h>\n", core),
            std::vector<std::string>{"line 2: #include <ros/ros.h>"});
  EXPECT_EQ(foreignIncludes("#include <sensor_msgs/JointState.h>\n", core).size(), 1u);
  EXPECT_EQ(foreignIncludes("#include \"cartpole_qlearning/EpisodeStats.h\"\n", core).size(), 1u);
  EXPECT_EQ(foreignIncludes("#include \"cartpole_qlearning/ros/start_up.h\"\n", core).size(), 1u);
  EXPECT_EQ(foreignIncludes("  #  include <boost/thread.hpp>\n", core).size(), 1u);
  EXPECT_EQ(foreignIncludes("#include <mujoco/mujoco.h>\n", core).size(), 1u);
}

TEST(CoreLayoutTest, ALayerMayIncludeItsOwnAndTheLayersBelowOnly)
{
  EXPECT_TRUE(isHeaderAtOrBelow("learning", "learning/q_table.h"));
  EXPECT_TRUE(isHeaderAtOrBelow("learning", "simulation/cartpole_dynamics.h"));
  EXPECT_FALSE(isHeaderAtOrBelow("learning", "protocol/lockstep_protocol.h"));
  EXPECT_FALSE(isHeaderAtOrBelow("common", "io/file_access.h"));
  EXPECT_TRUE(isHeaderAtOrBelow("io", "config/parameter_source.h"));
  EXPECT_FALSE(isHeaderAtOrBelow("config", "io/yaml_parameters.h"));
  EXPECT_FALSE(isHeaderAtOrBelow("application", "ros/start_up.h"));
  EXPECT_FALSE(isHeaderAtOrBelow("learning", "learning/no_such_header.h"));
}

TEST(CoreLayoutTest, NoCoreFileIncludesAHeaderFromOutsideTheCoreOrFromALayerAbove)
{
  std::size_t files = 0;
  for (const std::string& layer : kLayers)
  {
    for (const fs::path& folder : {kSource / "src" / layer, kSource / "include" / "cartpole_qlearning" / layer})
    {
      ASSERT_TRUE(fs::is_directory(folder)) << folder;
      for (const fs::directory_entry& entry : fs::directory_iterator(folder))
      {
        ASSERT_TRUE(entry.is_regular_file()) << entry.path() << ": a layer's folder holds files only";
        ++files;
        const auto allowed = [&layer](const std::string& name) { return isHeaderAtOrBelow(layer, name); };
        for (const std::string& line : foreignIncludes(withoutFolderIncludes(readText(entry.path()), folder), allowed))
        {
          // The MuJoCo engine, its own library (physics_engines.h), alone includes MuJoCo's headers.
          if (entry.path().filename() == "mujoco_engine.cpp" &&
              text_match::contains(line, "#include <mujoco/[a-z]+\\.h>"))
            continue;
          ADD_FAILURE() << entry.path().string() << " " << line << ": the " << layer
                        << " layer includes the standard library, POSIX, Eigen, yaml-cpp and the headers of its own "
                           "layer and of those below it only";
        }
      }
    }
  }
  EXPECT_GT(files, 40u) << "the core's files were not found under " << kSource;
  // Nothing of the core lies outside its layers.
  for (const fs::path& folder : {kSource / "src", kSource / "include" / "cartpole_qlearning"})
    for (const fs::directory_entry& entry : fs::directory_iterator(folder))
      EXPECT_FALSE(entry.is_regular_file()) << entry.path() << " lies outside the layers' folders";
}

TEST(CoreLayoutTest, TheNodesSettingsIncludeNoRosHeader)
{
  // The nodes' settings (src/node_settings/) are read without ROS, for their tests to run with YAML
  // text and no master: they may include the whole core and their own headers, nothing of ROS.
  const fs::path include = kSource / "include" / "cartpole_qlearning";
  const auto allowed = [&include](const std::string& name) {
    const std::string folder = name.substr(0, name.find('/'));
    return (layerRank(folder) < kLayers.size() || folder == "node_settings") && fs::is_regular_file(include / name);
  };
  std::size_t files = 0;
  for (const fs::path& folder : {kSource / "src" / "node_settings", include / "node_settings"})
  {
    ASSERT_TRUE(fs::is_directory(folder)) << folder;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder))
    {
      ++files;
      // The folder's private headers ("settings_parts.h") are its own.
      for (const std::string& line : foreignIncludes(withoutFolderIncludes(readText(entry.path()), folder), allowed))
        ADD_FAILURE() << entry.path().string() << " " << line << ": the nodes' settings include no ROS header";
    }
  }
  EXPECT_GT(files, 5u);
}

// The string literals of a C++ text, comments left out ("a" "b" are two; escapes kept as written).
std::vector<std::string> stringLiterals(const std::string& text)
{
  std::vector<std::string> literals;
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    if (text.compare(i, 2, "//") == 0)
      i = std::min(text.find('\n', i), text.size());
    else if (text.compare(i, 2, "/*") == 0)
      i = std::min(text.find("*/", i + 2), text.size()) + 1;
    else if (text[i] == '\'')
      for (++i; i < text.size() && text[i] != '\''; ++i)
        i += text[i] == '\\' ? 1 : 0;
    else if (text.compare(i, 2, "R\"") == 0)
    {
      const std::size_t open = text.find('(', i);
      const std::string close = ")" + text.substr(i + 2, open - i - 2) + "\"";
      const std::size_t end = text.find(close, open);
      literals.push_back(text.substr(open + 1, end - open - 1));
      i = end + close.size() - 1;
    }
    else if (text[i] == '"')
    {
      std::string literal;
      for (++i; i < text.size() && text[i] != '"'; ++i)
      {
        if (text[i] == '\\')
          literal += text[i++];
        literal += text[i];
      }
      literals.push_back(literal);
    }
  }
  return literals;
}

// What in a string names a setting as one front end's users type it: a private parameter
// ("~max_effort"; "~/" is a home), a launch argument ("joint_states:=") or an option ("--save").
std::vector<std::string> frontEndNames(const std::string& literal)
{
  std::vector<std::string> found;
  for (const text_match::Groups& m : text_match::allMatches(
           literal, R"re((^|[^A-Za-z0-9_])(~[a-z][a-z0-9_/]*|[a-z][a-z0-9_]*:=|--[a-z][a-z0-9-]*))re"))
    found.push_back(m[2]);
  return found;
}

TEST(CoreLayoutTest, TheNameCheckFindsParametersLaunchArgumentsAndOptions)
{
  EXPECT_EQ(stringLiterals("f(\"a\", 'b', \"c\\\"d\"); // \"e\"\n/* \"f\" */ R\"x(g)x\""),
            (std::vector<std::string>{"a", "c\\\"d", "g"}));
  EXPECT_EQ(frontEndNames("set ~load_on_start to a table"), std::vector<std::string>{"~load_on_start"});
  EXPECT_EQ(frontEndNames("(robot.launch joint_states:=)"), std::vector<std::string>{"joint_states:="});
  EXPECT_EQ(frontEndNames("give --save, or --ns"), (std::vector<std::string>{"--save", "--ns"}));
  EXPECT_TRUE(frontEndNames("~/tables, ~, a--b, --> 3, 5 -- 6, x := y").empty());
}

TEST(CoreLayoutTest, NoCoreStringNamesAParameterALaunchArgumentOrAnOption)
{
  // The core takes values and says what it did with them; which parameter or option set a value
  // is the front end's to say (common/setting_names.h: the core asks it by Setting).
  std::size_t literals = 0;
  for (const std::string& layer : kLayers)
  {
    for (const fs::path& folder : {kSource / "src" / layer, kSource / "include" / "cartpole_qlearning" / layer})
    {
      for (const fs::directory_entry& entry : fs::directory_iterator(folder))
      {
        for (const std::string& literal : stringLiterals(readText(entry.path())))
        {
          ++literals;
          for (const std::string& name : frontEndNames(literal))
            ADD_FAILURE() << entry.path().string() << ": \"" << literal << "\" names " << name
                          << ": name the Setting instead (common/setting_names.h), for the front end to spell";
        }
      }
    }
  }
  EXPECT_GT(literals, 1000u) << "the core's strings were not found under " << kSource;
}

// What in a file's text names a particular engine (its kind, or its name as a string): only the
// engines' own files and their registry (the simulation layer) may.
std::vector<std::string> engineNames(const std::string& text)
{
  std::vector<std::string> found;
  for (const text_match::Groups& m : text_match::allMatches(text, R"((EngineKind|"mujoco"|"equations"))"))
    found.push_back(m[1]);
  return found;
}

TEST(CoreLayoutTest, OnlyTheSimulationLayerNamesAnEngine)
{
  EXPECT_EQ(engineNames("if (engine.kind == EngineKind::Mujoco)\n"), std::vector<std::string>{"EngineKind"});
  EXPECT_EQ(engineNames("engine.name == \"mujoco\""), std::vector<std::string>{"\"mujoco\""});
  EXPECT_TRUE(engineNames("engineOf(engine).names_joints").empty());
  const fs::path include = kSource / "include" / "cartpole_qlearning";
  for (const fs::path& root : {kSource / "src", include})
  {
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root))
    {
      const fs::path folder = entry.path().parent_path();
      if (!entry.is_regular_file() || folder == kSource / "src" / "simulation" || folder == include / "simulation")
        continue;
      for (const std::string& name : engineNames(readText(entry.path())))
        ADD_FAILURE() << entry.path().string() << " names the engine " << name
                      << ": ask the registry (simulation/engine_registry.h) what the engine does instead";
    }
  }
}

// The names in backquotes in the Layout row (of docs/design.md) that starts with `first_cell`,
// leaving out paths and patterns (they name folders, not files). tools/readme_layout.py writes
// the table.
std::set<std::string> layoutNames(const std::string& page, const std::string& first_cell)
{
  const std::size_t layout = page.find("## Layout\n");
  const std::size_t row = page.find("\n| " + first_cell + " |", layout);
  std::set<std::string> names;
  if (layout == std::string::npos || row == std::string::npos)
    return names;
  const std::string line = page.substr(row + 1, page.find('\n', row + 1) - row - 1);
  const std::string cells = line.substr(first_cell.size() + 4);
  for (const text_match::Groups& quoted : text_match::allMatches(cells, "`([^`]+)`"))
  {
    const std::string& name = quoted[1];
    if (name.find('/') == std::string::npos && name.find('*') == std::string::npos)
      names.insert(name);
  }
  return names;
}

// The files of folders (stems: the name without its extension, for a header and source pair).
std::set<std::string> filesIn(const std::vector<fs::path>& folders, bool stems)
{
  std::set<std::string> names;
  for (const fs::path& folder : folders)
  {
    for (const fs::directory_entry& entry : fs::directory_iterator(folder))
    {
      if (entry.is_regular_file())
        names.insert(stems ? entry.path().stem().string() : entry.path().filename().string());
    }
  }
  return names;
}

TEST(CoreLayoutTest, TheLayoutTableListsTheTreeAsItIs)
{
  const std::string design = readText(kSource / "docs" / "design.md");
  const fs::path include = kSource / "include" / "cartpole_qlearning";
  struct Row
  {
    std::string first_cell;
    std::vector<fs::path> folders;
    bool stems;
  };
  const Row rows[] = {
      {"`include/cartpole_qlearning/common/`, `src/common/`", {include / "common", kSource / "src" / "common"}, true},
      {"`include/cartpole_qlearning/config/`, `src/config/`", {include / "config", kSource / "src" / "config"}, true},
      {"`include/cartpole_qlearning/io/`, `src/io/`", {include / "io", kSource / "src" / "io"}, true},
      {"`include/cartpole_qlearning/simulation/`, `src/simulation/`",
       {include / "simulation", kSource / "src" / "simulation"},
       true},
      {"`include/cartpole_qlearning/learning/`, `src/learning/`",
       {include / "learning", kSource / "src" / "learning"},
       true},
      {"`include/cartpole_qlearning/protocol/`, `src/protocol/`",
       {include / "protocol", kSource / "src" / "protocol"},
       true},
      {"`include/cartpole_qlearning/application/`, `src/application/`",
       {include / "application", kSource / "src" / "application"},
       true},
      {"`include/cartpole_qlearning/node_settings/`, `src/node_settings/`",
       {include / "node_settings", kSource / "src" / "node_settings"},
       true},
      {"`include/cartpole_qlearning/ros/`, `src/ros/`", {include / "ros", kSource / "src" / "ros"}, true},
      {"`src/cli/`", {kSource / "src" / "cli"}, true},
      {"`config/`", {kSource / "config"}, false},
      {"`launch/`", {kSource / "launch"}, false},
      {"`scripts/`", {kSource / "scripts"}, false},
      {"`tools/`", {kSource / "tools"}, false},
  };
  for (const Row& row : rows)
  {
    const std::set<std::string> listed = layoutNames(design, row.first_cell);
    const std::set<std::string> present = filesIn(row.folders, row.stems);
    for (const std::string& name : present)
      EXPECT_EQ(listed.count(name), 1u) << name << " is in the tree but not in docs/design.md's Layout row "
                                        << row.first_cell;
    for (const std::string& name : listed)
      EXPECT_EQ(present.count(name), 1u) << name << " is in docs/design.md's Layout row " << row.first_cell
                                         << " but not in the tree";
  }
}

}  // namespace
