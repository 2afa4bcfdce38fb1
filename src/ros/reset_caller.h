// A robot's reset service, called on threads of its own (see ResetCaller).
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/protocol/reset_calls.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace cartpole_qlearning
{
// Calls one robot's reset service (cartpole_qlearning/Reset, empty: a random start) whenever
// asked, on threads of its own, so that a robot whose call hangs holds up no other robot.
// roscpp's ServiceClient::call has no timeout: a sim stuck in its callback, a host gone with its
// TCP connection half-open, or a persistent link that hangs across a server's restart
// (ros/ros_comm#149, #152) can block a call for many minutes. When to call, retry and give a call
// up is ResetCalls' (reset_calls.h); this class makes the calls, logs what it says and wakes it at
// its times. A call given up leaves its thread blocked (detached; it shares only state held by
// shared_ptr, so it may outlive this object and the node) and a new thread takes the next calls.
class ResetCaller
{
public:
  // service: the service's resolved name; type: ~reset_service_type (cartpole_qlearning/Reset,
  // std_srvs/Empty or std_srvs/Trigger); give_up_after: resetGiveUpAfter(~sim_timeout); log: says
  // what ResetCalls says (the controller's log), called on this object's thread.
  ResetCaller(std::string service, std::string type, std::chrono::steady_clock::duration give_up_after,
              std::function<void(const LogLines&)> log);
  // Never waits for a call under way: gives it up as a hung one.
  ~ResetCaller();

  ResetCaller(const ResetCaller&) = delete;
  ResetCaller& operator=(const ResetCaller&) = delete;

  // A request made while a call is under way is served by the next call, not lost.
  void request();
  // The requests' outcomes since the last look, in order: true, the robot was reset; false, a call
  // failed or was given up (for RobotDispatch::onResetOutcome).
  std::vector<bool> outcomes();

private:
  struct Shared;
  // Feeds calls_ what happened (requests, calls back) and the time, and carries out its orders.
  void run();
  // Under shared_->mutex, on run()'s thread.
  void carryOut(const ResetCalls::Orders& orders);
  // A calling thread: makes the calls handed to its generation while it is the current one.
  static void callLoop(const std::shared_ptr<Shared>& shared, std::uint64_t generation, const std::string& service,
                       const std::string& type);

  const std::string service_;
  const std::string type_;
  const std::function<void(const LogLines&)> log_;
  ResetCalls calls_;  // run()'s only (a given-up thread must not touch this object)
  std::shared_ptr<Shared> shared_;
  std::thread caller_;  // the current calling thread, if any; run()'s only
  ResetCalls::Clock::time_point wake_at_ = ResetCalls::Clock::time_point::max();
  std::thread thread_;  // run()
};

}  // namespace cartpole_qlearning
