#include "start_up.h"

#include "launch_control.h"

#include <ros/callback_queue.h>
#include <ros/console.h>
#include <ros/init.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <map>
#include <mutex>
#include <utility>

namespace cartpole_qlearning
{
std::string nodeLogger(const std::string& type, const std::string& node_name)
{
  std::string name = node_name;
  std::replace(name.begin(), name.end(), '/', '.');
  if (!name.empty() && name.front() == '.')
    name.erase(0, 1);
  return name.empty() ? type : type + "." + name;
}

void logLine(const std::string& logger, ros::console::Level level, const std::string& text)
{
  // rosconsole keeps the address of every place it has set up (to update it when a level is
  // changed), so these are never freed.
  static std::mutex mutex;
  static auto* const places = new std::map<std::pair<std::string, int>, ros::console::LogLocation*>();
  ros::console::LogLocation* place = nullptr;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    ros::console::LogLocation*& found = (*places)[{logger, static_cast<int>(level)}];
    if (found == nullptr)
    {
      ROSCONSOLE_AUTOINIT;
      found = new ros::console::LogLocation{false, false, ros::console::levels::Count, nullptr};
      ros::console::initializeLogLocation(found, std::string(ROSCONSOLE_NAME_PREFIX) + "." + logger, level);
    }
    place = found;
  }
  if (place->logger_enabled_)
  {
    ros::console::print(nullptr, place->logger_, place->level_, __FILE__, __LINE__, __func__, "%s", text.c_str());
    // Under roslaunch into a file or a pipe stdout is block-buffered, and a line cut at the
    // buffer's end was finished after roslaunch's "killing on exit" lines (a SOLVED line split in
    // two, found by tools/first_hour.sh): each line leaves whole, when it is said.
    std::fflush(stdout);
  }
}

std::string withPrefix(const std::string& prefix, const LogLine& line)
{
  return line.prefixed ? prefix + line.text : line.text;
}

void logLine(const std::string& logger, LogLine::Level level, const std::string& text)
{
  static const ros::console::Level kLevels[] = {ros::console::levels::Info, ros::console::levels::Warn,
                                                ros::console::levels::Error};
  logLine(logger, kLevels[static_cast<int>(level)], text);
}

bool startNode(const std::string& type, const std::string& node_name, const std::function<void()>& start,
               std::string* reason, bool end_launch)
{
  // Only the start-up is caught here: an exception from a callback later is a crash like any
  // other, and under train.launch the node respawns.
  try
  {
    start();
    return true;
  }
  catch (const std::exception& e)
  {
    // The logger the node logs on afterwards.
    const std::string logger = nodeLogger(type, node_name);
    logLine(logger, ros::console::levels::Fatal, type + ": " + e.what());
    if (end_launch && endParentLaunch())
      logLine(logger, ros::console::levels::Fatal,
              type + ": ending the launch: this cannot work until the above is fixed");
    if (reason != nullptr)
      *reason = e.what();
    return false;
  }
}

bool takeCheckFlag(int& argc, char** argv)
{
  const std::string flag = "--check-parameters";
  const auto end = argv + argc;
  const auto found = std::find_if(argv + 1, end, [&](const char* arg) { return flag == arg; });
  if (found == end)
    return false;
  std::rotate(found, found + 1, end);
  --argc;
  return true;
}

namespace
{
std::atomic<bool> g_stop_requested{false};

void requestStop(int)
{
  g_stop_requested = true;
}
}  // namespace

void noteStopSignals()
{
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
}

void spinUntilStopped(double period_s, bool always_stop, const std::function<void()>& stop)
{
  while (ros::ok() && !g_stop_requested)
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(period_s));
  if (!g_stop_requested && !always_stop)
    return;
  stop();
  ros::WallDuration(0.2).sleep();
  ros::shutdown();
}

}  // namespace cartpole_qlearning
