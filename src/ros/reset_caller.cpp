#include "cartpole_qlearning/ros/reset_caller.h"

#include "cartpole_qlearning/Reset.h"

#include <ros/ros.h>

#include <condition_variable>
#include <mutex>
#include <utility>

namespace cartpole_qlearning
{
// What a ResetCaller and its calling threads share. A calling thread that was given up holds it
// after the ResetCaller is gone, so it is all the thread may touch.
struct ResetCaller::Shared
{
  std::mutex mutex;
  std::condition_variable changed;
  bool pending = false;   // a reset is wanted
  bool stopping = false;  // the ResetCaller is going away
  // The one calling thread whose answers count; a thread given up sees another number and ends.
  std::uint64_t generation = 0;
  // Given-up threads still blocked in their call. While one is, the next call is not given up
  // too: a sim stuck in its callback would otherwise cost a thread and a socket every give-up.
  int blocked = 0;
  // A call handed to the current thread, and its answer.
  bool asked = false;
  bool persistent = true;
  bool done = false;
  bool answered = false;
  std::string message;
};

ResetCaller::ResetCaller(std::string service, std::chrono::steady_clock::duration give_up_after)
  : service_(std::move(service)), give_up_after_(give_up_after), shared_(std::make_shared<Shared>())
{
  caller_ = std::thread(&ResetCaller::callLoop, shared_, shared_->generation, service_);
  thread_ = std::thread(&ResetCaller::run, this);
}

ResetCaller::~ResetCaller()
{
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->stopping = true;
  }
  shared_->changed.notify_all();
  thread_.join();
}

void ResetCaller::request()
{
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->pending = true;
  }
  shared_->changed.notify_all();
}

void ResetCaller::callLoop(const std::shared_ptr<Shared>& shared, std::uint64_t generation, const std::string& service)
{
  // Made by name (resolved already), not through a NodeHandle: a thread given up may outlive the
  // node and its handles.
  ros::ServiceClient persistent_client;
  for (;;)
  {
    bool persistent = true;
    {
      std::unique_lock<std::mutex> lock(shared->mutex);
      shared->changed.wait(lock, [&] { return shared->stopping || shared->generation != generation || shared->asked; });
      if (shared->generation != generation)
      {
        // Given up before it even took its call (a starved thread): counted as blocked all the same.
        --shared->blocked;
        shared->changed.notify_all();
        return;
      }
      if (shared->stopping)
        return;
      shared->asked = false;
      persistent = shared->persistent;
    }
    Reset reset;  // empty state: a random start
    bool answered = false;
    if (persistent)
    {
      // Connected when first needed (the sim may come up after this node). Persistent: a new
      // connection per episode would cost a master lookup and a TCP set-up.
      if (!persistent_client.isValid())
        persistent_client = ros::ServiceClient(service, true, ros::M_string(), ros::service_traits::md5sum<Reset>());
      answered = persistent_client.call(reset) && reset.response.success;
    }
    else
    {
      // While the sim is away or restarting, each try makes a connection of its own: roscpp's
      // persistent links can hang across a server's restart (ros/ros_comm#149, #152). The
      // persistent link is made again once the sim answers.
      persistent_client = ros::ServiceClient();
      answered =
          ros::ServiceClient(service, false, ros::M_string(), ros::service_traits::md5sum<Reset>()).call(reset) &&
          reset.response.success;
    }
    {
      std::lock_guard<std::mutex> lock(shared->mutex);
      if (shared->generation != generation)
      {
        --shared->blocked;  // given up while the call hung: nobody waits for this answer any more
        shared->changed.notify_all();
        return;
      }
      if (shared->stopping)
        return;
      shared->done = true;
      shared->answered = answered;
      shared->message = reset.response.message;
    }
    shared->changed.notify_all();
  }
}

void ResetCaller::run()
{
  // A failing robot is called again no sooner than this later, not in a tight loop.
  const auto retry_after = std::chrono::milliseconds(200);
  auto retry_at = std::chrono::steady_clock::time_point::min();
  bool failing = false;
  std::unique_lock<std::mutex> lock(shared_->mutex);
  for (;;)
  {
    while (!shared_->stopping && !(shared_->pending && std::chrono::steady_clock::now() >= retry_at))
    {
      if (shared_->pending)
        shared_->changed.wait_until(lock, retry_at);
      else
        shared_->changed.wait(lock);
    }
    if (shared_->stopping)
      break;
    // Taken before the call: a request made while the call is under way (a short episode can
    // end before the answer comes) is then served by the next call, not lost.
    shared_->pending = false;
    shared_->asked = true;
    shared_->persistent = !failing;
    shared_->done = false;
    shared_->changed.notify_all();
    const auto give_up_at = std::chrono::steady_clock::now() + give_up_after_;
    // A call given up earlier and still blocked: this one is waited for as long as it takes (a
    // third connection would hang behind the same stuck sim).
    if (!shared_->changed.wait_until(lock, give_up_at, [&] { return shared_->done || shared_->stopping; }) &&
        shared_->blocked > 0)
      shared_->changed.wait(lock, [&] { return shared_->done || shared_->stopping; });
    if (!shared_->done && !shared_->stopping)
    {
      ++shared_->generation;
      ++shared_->blocked;
      caller_.detach();
      ROS_WARN(
          "qlearning_controller: reset call to %s has not returned after %.1f s; giving it up and retrying on a "
          "new connection",
          service_.c_str(), std::chrono::duration<double>(give_up_after_).count());
      failing = true;
      shared_->pending = true;
      retry_at = std::chrono::steady_clock::now();
      caller_ = std::thread(&ResetCaller::callLoop, shared_, shared_->generation, service_);
      continue;
    }
    if (!shared_->done)
    {
      // Stopping while a call is under way: it is given up, as a hung one, without a wait.
      ++shared_->generation;
      ++shared_->blocked;
      caller_.detach();
      return;
    }
    if (shared_->answered)
    {
      if (failing)
        ROS_INFO("qlearning_controller: %s answers again; going on", service_.c_str());
      failing = false;
      continue;
    }
    if (!failing)
      ROS_WARN("qlearning_controller: reset call to %s failed%s; retrying until it answers", service_.c_str(),
               shared_->message.empty() ? "" : (": " + shared_->message).c_str());
    failing = true;
    shared_->pending = true;
    retry_at = std::chrono::steady_clock::now() + retry_after;
  }
  // No call under way: the calling thread sees stopping and ends at once.
  lock.unlock();
  caller_.join();
}

}  // namespace cartpole_qlearning
