#include "launch_control.h"

#include <fstream>
#include <iterator>
#include <sstream>

#include <signal.h>
#include <unistd.h>

namespace cartpole_qlearning
{
namespace
{
// The program a process runs, by its command line: "roslaunch" for "python3 /usr/bin/roslaunch
// ..." (or the script run directly), else the first word's last path component.
std::string programOf(pid_t pid)
{
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream args(text);
  std::string arg;
  std::string first;
  for (int i = 0; i < 2 && std::getline(args, arg, '\0'); ++i)
  {
    const std::string name = arg.substr(arg.find_last_of('/') + 1);
    if (name == "roslaunch" || name == "rostest")
      return name;
    if (i == 0)
      first = name;
  }
  return first;
}

pid_t parentOf(pid_t pid)
{
  // /proc/<pid>/stat: "pid (comm) state ppid ..."; comm may hold spaces, so read after the last ')'.
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t close = text.rfind(')');
  if (close == std::string::npos)
    return 0;
  std::istringstream rest(text.substr(close + 1));
  std::string state;
  long parent = 0;
  rest >> state >> parent;
  return static_cast<pid_t>(parent);
}

// The roslaunch this process runs under, or 0: the parent, or an ancestor a few levels up when a
// launch-prefix (gdb, valgrind, xterm) stands between. Under rostest: none (rostest runs its
// own launch; ending it would end the test).
}  // namespace

pid_t launchingRoslaunch()
{
  pid_t pid = ::getppid();
  for (int level = 0; level < 4 && pid > 1; ++level)
  {
    const std::string program = programOf(pid);
    if (program == "roslaunch")
      return pid;
    if (program == "rostest")
      return 0;
    pid = parentOf(pid);
  }
  return 0;
}

bool startedByRoslaunch()
{
  return launchingRoslaunch() > 0;
}

bool endParentLaunch()
{
  const pid_t roslaunch = launchingRoslaunch();
  return roslaunch > 0 && ::kill(roslaunch, SIGINT) == 0;
}

}  // namespace cartpole_qlearning
