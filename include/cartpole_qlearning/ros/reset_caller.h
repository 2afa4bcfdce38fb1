// A robot's reset service, called on threads of its own (see ResetCaller).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

namespace cartpole_qlearning
{
// Calls one robot's reset service (cartpole_qlearning/Reset, empty: a random start) whenever
// asked, on threads of its own, so that a robot whose call hangs holds up no other robot.
// roscpp's ServiceClient::call has no timeout: a sim stuck in its callback, a host gone with its
// TCP connection half-open, or a persistent link that hangs across a server's restart
// (ros/ros_comm#149, #152) can block a call for many minutes. A call still under way after
// give_up_after is given up: its thread is left blocked (detached; it shares only state held by
// shared_ptr, so it may outlive this object and the node) and a fresh thread retries on a new
// connection.
class ResetCaller
{
public:
  // service: the service's resolved name.
  ResetCaller(std::string service, std::chrono::steady_clock::duration give_up_after);
  // Never waits for a call under way: gives it up as a hung one.
  ~ResetCaller();

  ResetCaller(const ResetCaller&) = delete;
  ResetCaller& operator=(const ResetCaller&) = delete;

  // A request made while a call is under way is served by the next call, not lost.
  void request();

private:
  struct Shared;
  // Hands each wanted reset to the current calling thread and waits for its answer, at most
  // give_up_after; retries a failing robot.
  void run();
  // A calling thread: makes the calls it is handed while it is the current one (generation).
  static void callLoop(const std::shared_ptr<Shared>& shared, std::uint64_t generation, const std::string& service);

  const std::string service_;
  const std::chrono::steady_clock::duration give_up_after_;
  std::shared_ptr<Shared> shared_;
  std::thread caller_;  // the current calling thread; used by run() only, until it ends
  std::thread thread_;  // run()
};

}  // namespace cartpole_qlearning
