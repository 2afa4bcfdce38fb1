// Helpers the tests share, without ROS: running a command as a user would, reading a file.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
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

// The same doubles to the bit (NaN payloads and the sign of zero included), as a saved table
// and a replayed run must be.
inline bool bitIdentical(const std::vector<double>& a, const std::vector<double>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

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

// Every file below a folder, as "relative/path", sorted.
inline std::vector<std::string> filesBelow(const std::filesystem::path& folder)
{
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder))
  {
    if (!entry.is_directory())
      found.push_back(std::filesystem::relative(entry.path(), folder).string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

inline std::string fileText(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// True once `pid` has exited: no such process, or a zombie its parent has not reaped yet.
inline bool processGone(int pid)
{
  std::string stat = fileText("/proc/" + std::to_string(pid) + "/stat");
  // The state follows the command name in parentheses, which may itself hold ") ".
  const std::size_t name_end = stat.rfind(')');
  return stat.empty() || name_end == std::string::npos || stat.compare(name_end + 1, 3, " Z ") == 0 ||
         stat.compare(name_end + 1, 3, " X ") == 0;
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
  // Waits for the end and returns waitpid's status (0 when it was stopped already).
  int wait()
  {
    int status = 0;
    if (pid_ > 0)
      ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }
  pid_t pid() const
  {
    return pid_;
  }

private:
  pid_t pid_ = -1;
};

// `roslaunch cartpole_qlearning train.launch ARGS` (or another of the package's launch files) in
// the background, as a user runs it, with ROS_HOME set to `ros_home` (tables, logs) and its whole
// output, nodes included, in ros_home/NAME.log. Ended with Ctrl-C (SIGINT) if still running when
// it goes out of scope.
class TrainLaunch
{
public:
  TrainLaunch(const std::string& ros_home, const std::string& name, const std::string& args,
              const std::string& launch_file = "train.launch")
    : log_(ros_home + "/" + name + ".log")
  {
    const std::string roslaunch = runCommand("command -v roslaunch").lastLine();
    pid_ = startProcess(
        "/bin/sh",
        {"-c", "exec " + roslaunch + " cartpole_qlearning " + launch_file + " " + args + " >" + log_ + " 2>&1"},
        {"ROS_HOME=" + ros_home, "PYTHONUNBUFFERED=1"});
  }
  ~TrainLaunch()
  {
    if (pid_ > 0)
    {
      ::kill(pid_, SIGINT);
      waitFor(30.0);
    }
  }
  TrainLaunch(const TrainLaunch&) = delete;
  TrainLaunch& operator=(const TrainLaunch&) = delete;

  // The exit status (128 + N for signal N), or -1 when it did not end in time.
  int waitFor(double seconds)
  {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (pid_ > 0 && std::chrono::steady_clock::now() < deadline)
    {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_)
      {
        pid_ = -1;
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return status_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return pid_ > 0 ? -1 : status_;
  }
  std::string output() const
  {
    return fileText(log_);
  }
  // Ctrl-C, as a user stops a launch; the exit status as waitFor gives it.
  int interrupt(double seconds)
  {
    if (pid_ > 0)
      ::kill(pid_, SIGINT);
    return waitFor(seconds);
  }

private:
  pid_t pid_ = -1;
  int status_ = -1;
  std::string log_;
};

}  // namespace test
}  // namespace cartpole_qlearning
