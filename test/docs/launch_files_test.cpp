// The launch files' check of their parameters (scripts/check_launch) against the files: a launch
// that users type checks its parameters before any node starts, and hands the check every
// argument a user can give it. An argument added to a launch and not to its check line would
// let that argument's refused values through to the nodes (roslaunch then exits 0): that fails
// here with the names.
#include "test_support.h"

#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <regex>
#include <set>
#include <string>

namespace fs = std::filesystem;
using cartpole_qlearning::test::fileText;

namespace
{
const fs::path kLaunch = fs::path(CARTPOLE_SOURCE_DIR) / "launch";

// The arguments a user gives (<arg name="..." [default="..."] doc="...">; those with value= are the file's own).
std::set<std::string> userArguments(const std::string& text)
{
  std::set<std::string> names;
  const std::regex arg(R"re(<arg name="([a-z_]+)"(?: default="[^"]*")? doc=)re");
  for (std::sregex_iterator it(text.begin(), text.end(), arg), end; it != end; ++it)
    names.insert((*it)[1]);
  names.erase("check_parameters");  // the check's own switch
  return names;
}

// The command of the check's <param>, "" when the file has none.
std::string checkCommand(const std::string& text)
{
  std::smatch found;
  const std::regex param(R"re(<param if="\$\(arg check_parameters\)"[^>]*command="([^"]*)")re");
  return std::regex_search(text, found, param) ? found[1].str() : "";
}

std::set<std::string> passedArguments(const std::string& command)
{
  std::set<std::string> names;
  const std::regex passed(R"re('([a-z_]+):=\$\(arg ([a-z_]+)\)')re");
  for (std::sregex_iterator it(command.begin(), command.end(), passed), end; it != end; ++it)
    if ((*it)[1] == (*it)[2])
      names.insert((*it)[1]);
  return names;
}
}  // namespace

TEST(LaunchFilesTest, EachLaunchChecksItsParametersWithEveryArgumentItTakes)
{
  int checked = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kLaunch))
  {
    const fs::path file = entry.path();
    if (file.extension() != ".launch")
      continue;
    const std::string text = fileText(file.string());
    const std::string command = checkCommand(text);
    // Its nodes run on other hosts, whose files and builds this one cannot see.
    if (file.filename() == "train_across_hosts.launch")
    {
      EXPECT_EQ("", command);
      continue;
    }
    ASSERT_NE("", command) << file.filename() << " starts nodes without checking their parameters";
    const std::string itself = "check_launch $(find cartpole_qlearning)/launch/" + file.filename().string();
    const std::size_t at = command.find(itself);
    EXPECT_TRUE(at != std::string::npos && std::isspace(static_cast<unsigned char>(command[at + itself.size()])))
        << file.filename() << " checks another file: " << command;
    EXPECT_EQ(userArguments(text), passedArguments(command)) << file.filename()
                                                             << ": the arguments a user gives "
                                                                "and those its check is given differ";
    ++checked;
  }
  EXPECT_EQ(5, checked) << "evaluate, robot, sim, train and try_robot.launch";
}

// An including launch checks the whole of what it starts, and the file it includes does not check
// again (its check would run the package's nodes a second time before anything starts).
TEST(LaunchFilesTest, AnIncludedLaunchIsCheckedByTheLaunchThatIncludesIt)
{
  const std::string text = fileText((kLaunch / "try_robot.launch").string());
  const std::regex include(
      R"re(<include file="\$\(find cartpole_qlearning\)/launch/robot.launch">([\s\S]*?)</include>)re");
  std::smatch found;
  ASSERT_TRUE(std::regex_search(text, found, include));
  EXPECT_NE(std::string::npos, found[1].str().find(R"(<arg name="check_parameters" value="false"/>)"));
}
