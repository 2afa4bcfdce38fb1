#include "cartpole_qlearning/launch_control.h"

#include <fstream>
#include <iterator>
#include <sstream>

#include <signal.h>
#include <unistd.h>

namespace cartpole_qlearning
{
bool startedByRoslaunch()
{
  const pid_t parent = ::getppid();
  if (parent <= 1)
    return false;
  // The parent's command line, NUL-separated: "python3 /usr/bin/roslaunch pkg file ..." (or the
  // script itself first, when run directly).
  std::ifstream in("/proc/" + std::to_string(parent) + "/cmdline", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream args(text);
  std::string arg;
  for (int i = 0; i < 2 && std::getline(args, arg, '\0'); ++i)
  {
    const std::string name = arg.substr(arg.find_last_of('/') + 1);
    if (name == "roslaunch")
      return true;
  }
  return false;
}

bool endParentLaunch()
{
  if (!startedByRoslaunch())
    return false;
  return ::kill(::getppid(), SIGINT) == 0;
}

}  // namespace cartpole_qlearning
