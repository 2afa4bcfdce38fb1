// Helpers the tests share, without ROS: running a command as a user would, reading a file.
#pragma once

#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <signal.h>
#include <unistd.h>

#include <sys/wait.h>

namespace cartpole_qlearning
{
namespace test
{
struct CommandRun
{
  int status = -1;     // the exit status; -1 when the command did not exit normally
  std::string output;  // stdout and stderr together
  double seconds = 0.0;

  std::string lastLine() const
  {
    std::string text = output;
    while (!text.empty() && text.back() == '\n')
      text.pop_back();
    return text.substr(text.find_last_of('\n') + 1);
  }
};

// Runs a shell command, its stderr joined to its stdout, and waits for it.
inline CommandRun runCommand(const std::string& command)
{
  CommandRun run;
  const auto start = std::chrono::steady_clock::now();
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr)
    return run;
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

inline std::string fileText(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Starts an executable with arguments (and extra NAME=VALUE environment entries) in the
// background; returns its pid.
inline pid_t startProcess(const std::string& executable, const std::vector<std::string>& args,
                          const std::vector<std::string>& environment = {})
{
  const pid_t pid = ::fork();
  if (pid == 0)
  {
    for (const std::string& entry : environment)
      ::putenv(const_cast<char*>(entry.c_str()));
    std::vector<char*> argv{const_cast<char*>(executable.c_str())};
    for (const std::string& a : args)
      argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(executable.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

// Sends the signal and waits for the process to end.
inline void stopProcess(pid_t pid, int signal)
{
  ::kill(pid, signal);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

// A process a test started: stopped with SIGKILL and reaped however the test ends (a failed
// ASSERT returns early), so a failing run leaves no node behind to load the machine.
class ChildProcess
{
public:
  ChildProcess() = default;
  ChildProcess(const std::string& executable, const std::vector<std::string>& args,
               const std::vector<std::string>& environment = {})
    : pid_(startProcess(executable, args, environment))
  {
  }
  ~ChildProcess()
  {
    stop(SIGKILL);
  }
  ChildProcess(ChildProcess&& other) noexcept : pid_(other.pid_)
  {
    other.pid_ = -1;
  }
  ChildProcess& operator=(ChildProcess&& other) noexcept
  {
    if (this != &other)
    {
      stop(SIGKILL);
      pid_ = other.pid_;
      other.pid_ = -1;
    }
    return *this;
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Sends the signal and waits for the end (nothing when it was stopped already).
  void stop(int signal)
  {
    if (pid_ > 0)
      stopProcess(pid_, signal);
    pid_ = -1;
  }
  pid_t pid() const
  {
    return pid_;
  }

private:
  pid_t pid_ = -1;
};

}  // namespace test
}  // namespace cartpole_qlearning
