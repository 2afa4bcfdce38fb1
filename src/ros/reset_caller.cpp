#include "reset_caller.h"

#include "cartpole_qlearning/Reset.h"
#include "service_probe.h"

#include "cartpole_qlearning/node_settings/node_setting_names.h"

#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/Trigger.h>

#include <condition_variable>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

namespace cartpole_qlearning
{
namespace
{
bool succeeded(const Reset::Response& response, std::string& message)
{
  message = response.message;
  return response.success;
}
bool succeeded(const std_srvs::Trigger::Response& response, std::string& message)
{
  message = response.message;
  return response.success;
}
bool succeeded(const std_srvs::Empty::Response&, std::string&)
{
  return true;  // Gazebo's reset_simulation and many drivers' reset: an answer is a reset
}

// How long a failed call's probe of the service may wait for each of its steps (rosservice's own
// is 1 s too): it holds up this robot's next retry, never the control loop.
constexpr std::chrono::milliseconds kProbeTimeout(1000);

// One call of a reset service of type Srv (ours with an empty state: a random start). Persistent:
// on persistent_client, connected when first needed (the sim may come up after this node; a new
// connection per episode would cost a master lookup and a TCP set-up); else on a connection of
// its own (see ResetCalls), and the persistent link is made again once the sim answers.
// went_through: the call itself was made (false: no server, or one that refused our type).
template <typename Srv>
bool callReset(ros::ServiceClient& persistent_client, const std::string& service, bool persistent, std::string& message,
               bool& went_through)
{
  Srv srv;
  ros::ServiceClient once;
  if (!persistent)
    persistent_client = ros::ServiceClient();
  ros::ServiceClient& client = persistent ? persistent_client : once;
  if (!client.isValid())
    client = ros::ServiceClient(service, persistent, ros::M_string(), ros::service_traits::md5sum<Srv>());
  went_through = client.call(srv);
  return went_through && succeeded(srv.response, message);
}

std::string md5sumOf(const std::string& type)
{
  return type == "std_srvs/Empty"     ? ros::service_traits::md5sum<std_srvs::Empty>()
         : type == "std_srvs/Trigger" ? ros::service_traits::md5sum<std_srvs::Trigger>()
                                      : ros::service_traits::md5sum<Reset>();
}
}  // namespace

// What a ResetCaller and its calling threads share. A calling thread that was given up holds it
// after the ResetCaller is gone, so it is all the thread may touch.
struct ResetCaller::Shared
{
  // A call back, for run() to feed to ResetCalls.
  struct Returned
  {
    std::uint64_t generation = 0;
    bool called = true;  // false: the thread was given up before it took its call
    bool answered = false;
    std::string message;
    ServiceFound found;  // a call that did not go through: what the service turned out to be
  };

  std::mutex mutex;
  std::condition_variable changed;
  bool stopping = false;   // the ResetCaller is going away
  bool requested = false;  // request() since run() last looked
  std::vector<Returned> returned;
  // The calling thread whose calls count; a thread of another generation was given up and ends.
  std::uint64_t generation = 0;
  // A call handed to the current thread: on the persistent connection or a fresh one.
  std::optional<bool> handed;
  std::vector<bool> outcomes;  // ResetCalls' reset_done, until outcomes() takes them
};

ResetCaller::ResetCaller(std::string service, std::string type, std::chrono::steady_clock::duration give_up_after,
                         std::function<void(const LogLines&)> log)
  : service_(std::move(service)),
    type_(std::move(type)),
    log_(std::move(log)),
    calls_(service_, type_, md5sumOf(type_), give_up_after, std::chrono::milliseconds(200), nodeSettingNames()),
    shared_(std::make_shared<Shared>())
{
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
    shared_->requested = true;
  }
  shared_->changed.notify_all();
}

std::vector<bool> ResetCaller::outcomes()
{
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  return std::exchange(shared_->outcomes, {});
}

void ResetCaller::callLoop(const std::shared_ptr<Shared>& shared, std::uint64_t generation, const std::string& service,
                           const std::string& type)
{
  // Made by name (resolved already), not through a NodeHandle: a thread given up may outlive the
  // node and its handles.
  ros::ServiceClient persistent_client;
  for (;;)
  {
    bool persistent = true;
    {
      std::unique_lock<std::mutex> lock(shared->mutex);
      shared->changed.wait(lock,
                           [&] { return shared->stopping || shared->generation != generation || shared->handed; });
      if (shared->generation != generation)
      {
        // Given up before it even took its call (a starved thread): it frees its slot all the same.
        shared->returned.push_back({generation, false, false, "", {}});
        shared->changed.notify_all();
        return;
      }
      if (shared->stopping)
        return;
      persistent = *shared->handed;
      shared->handed.reset();
    }
    std::string message;
    bool went_through = false;
    const bool answered =
        type == "std_srvs/Empty"
            ? callReset<std_srvs::Empty>(persistent_client, service, persistent, message, went_through)
        : type == "std_srvs/Trigger"
            ? callReset<std_srvs::Trigger>(persistent_client, service, persistent, message, went_through)
            : callReset<Reset>(persistent_client, service, persistent, message, went_through);
    // A call that did not go through: is the service missing, or of another type? Asked here, on
    // this robot's calling thread, with a timeout of its own.
    ServiceFound found;
    if (!went_through && ros::ok())
      found = probeService(service, ros::this_node::getName(), kProbeTimeout);
    {
      std::lock_guard<std::mutex> lock(shared->mutex);
      shared->returned.push_back({generation, true, answered, message, found});
      shared->changed.notify_all();
      if (shared->generation != generation || shared->stopping)
        return;
    }
  }
}

void ResetCaller::run()
{
  std::unique_lock<std::mutex> lock(shared_->mutex);
  const auto woken = [this] { return shared_->stopping || shared_->requested || !shared_->returned.empty(); };
  for (;;)
  {
    if (wake_at_ == ResetCalls::Clock::time_point::max())
      shared_->changed.wait(lock, woken);
    else
      shared_->changed.wait_until(lock, wake_at_, woken);
    const auto now = ResetCalls::Clock::now();
    for (const Shared::Returned& back : std::exchange(shared_->returned, {}))
      carryOut(back.called ? calls_.onReturn(back.generation, back.answered, back.message, now, back.found)
                           : calls_.onThreadEnded(back.generation, now));
    if (shared_->stopping)
      break;
    if (std::exchange(shared_->requested, false))
      carryOut(calls_.request(now));
    carryOut(calls_.onTime(now));
  }
  carryOut(calls_.stop());
  // No call under way any more: a thread still current sees stopping and ends at once.
  lock.unlock();
  if (caller_.joinable())
    caller_.join();
}

void ResetCaller::carryOut(const ResetCalls::Orders& orders)
{
  if (orders.give_up && caller_.joinable())
    caller_.detach();  // blocked in its call, or about to see that it was given up
  shared_->generation = calls_.generation();
  if (!orders.log.empty() && log_)
    log_(orders.log);
  if (orders.call)
  {
    if (!caller_.joinable())
      caller_ = std::thread(&ResetCaller::callLoop, shared_, orders.call->generation, service_, type_);
    shared_->handed = orders.call->persistent;
  }
  if (orders.give_up || orders.call)
    shared_->changed.notify_all();
  wake_at_ = orders.wake_at;
  if (orders.reset_done)
    shared_->outcomes.push_back(*orders.reset_done);
}

}  // namespace cartpole_qlearning
