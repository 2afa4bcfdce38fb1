// When to call a robot's reset service, when to give a call up and what to say about it, without
// ROS. ResetCaller (ros/reset_caller.h) makes the calls on threads of its own, feeds this class
// what happens and carries out what it decides.
//
// The rules:
//   - A request starts a call at once when none is under way; one made during a call (a short
//     episode can end before the answer comes) is served by the next call, never lost, and
//     several such requests make one call.
//   - Calls go on a persistent connection while the robot answers. A failed call (the call
//     itself, or success false) is said once and retried no sooner than retry_after later, and
//     then on fresh connections: roscpp's persistent links can hang across a server's restart
//     (ros/ros_comm#149, #152). The first answer after that is said, and the calls go back to
//     a persistent connection.
//   - A call still under way give_up_after after it started is given up (said every time): its
//     thread is left blocked, and the request is retried at once on a fresh connection, on a
//     new thread (the next generation).
//   - At most one given-up call may still be blocked: while one is, the call under way is not
//     given up but waited for as long as it takes (a third connection would hang behind the
//     same stuck sim, and each give-up costs a thread and a socket). A given-up thread frees
//     its slot when it ends, whether its call came back (late: its answer is ignored) or it was
//     given up before it even took its call.
//   - stop() gives up a call under way without a wait; after it nothing more is called.
//   - A failed call comes back with what the service turned out to be (asked the way rosservice
//     info asks: ServiceFound). A service nobody advertises is said to be missing, one that
//     serves another type than ~reset_service_type is named with the type it serves, as errors:
//     no retry can make such a call work, the user has to. Each is said once while the calls
//     fail, and again when what is found changes (the sim came up, of another type). A service
//     of another type is retried every 5 s only (each call makes its server log an error).
//   - Every call back and every give-up is an outcome (Orders::reset_done) for the protocol: a
//     failed reset leaves the robot where it fell (lockstep_protocol.h).
//
// Identity: every call carries the generation of the thread that makes it. Calls of one
// generation are made one after the other, so an answer is matched to its call by generation
// alone, and an answer of a generation given up is never taken for the current call's.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/common/setting_names.h"

#include <chrono>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// How long a reset call may take before it is given up: max(5 s, 2 x sim_timeout), long enough
// for a sim that is merely slow (loaded, or far away), since a give-up leaves a thread and a
// connection behind (sim_timeout is how long the user lets a sim be silent before calling it
// gone). At most an hour: a huge sim_timeout must not overflow the clock's arithmetic.
std::chrono::steady_clock::duration resetGiveUpAfter(double sim_timeout_s);

// The types a reset service may have (~reset_service_type), the controller's own first.
const std::vector<std::string>& resetServiceTypes();

// What a failed call's service turned out to be: the master's lookupService, and the header its
// server answers a probe with (what `rosservice info` shows).
struct ServiceFound
{
  enum class Kind
  {
    Unknown,  // not found out (the probe failed or timed out): only the call's failure is said
    Missing,  // the master knows no node that advertises it
    Served    // a node serves it: type and md5sum are what its header says
  };
  Kind kind = Kind::Unknown;
  std::string type;
  std::string md5sum;
};

class ResetCalls
{
public:
  using Clock = std::chrono::steady_clock;

  struct Call
  {
    std::uint64_t generation = 0;  // the thread to make it on (a new one after a give-up)
    bool persistent = true;        // false: a connection of its own, closed after the call
  };

  // What to do after an event, in this order.
  struct Orders
  {
    // Give up the call of this generation: leave its thread blocked (it ends on its own).
    std::optional<std::uint64_t> give_up;
    LogLines log;
    std::optional<Call> call;  // make this call now
    // Feed onTime() at this time at the latest (Clock::time_point::max(): not before an event).
    Clock::time_point wake_at = Clock::time_point::max();
    // A call came back or was given up: true, the robot was reset; false, it was not (for the
    // protocol: ControllerProtocol::onResetOutcome).
    std::optional<bool> reset_done;
  };

  // service: the service's name, for what is said; type and md5sum: the type the calls are made
  // with (~reset_service_type) and its md5sum, to tell a service of another type; give_up_after:
  // see resetGiveUpAfter(); retry_after: how long a failing robot is left alone between calls;
  // names: how the front end names the settings a failure points at (the reset service, its type,
  // the start region).
  ResetCalls(std::string service, std::string type, std::string md5sum, Clock::duration give_up_after,
             Clock::duration retry_after = std::chrono::milliseconds(200), SettingNames names = {});

  // A reset is wanted.
  Orders request(Clock::time_point now);
  // The call made on generation came back: answered (the call went through and the response says
  // success) or not, with the response's message and, when not, what the service turned out to be.
  Orders onReturn(std::uint64_t generation, bool answered, const std::string& message, Clock::time_point now,
                  const ServiceFound& found = {});
  // The thread of a given-up generation ended without making its call (given up before it took
  // it).
  Orders onThreadEnded(std::uint64_t generation, Clock::time_point now);
  // The time: gives up a call due for it, makes a retry that is due.
  Orders onTime(Clock::time_point now);
  // No more calls: a call under way is given up, without a wait.
  Orders stop();

  // The generation whose answers count (a thread of another one was given up).
  std::uint64_t generation() const
  {
    return generation_;
  }
  // Given-up calls still blocked (at most one).
  std::size_t blocked() const
  {
    return blocked_.size();
  }

private:
  enum class Phase
  {
    Idle,     // no call under way
    Calling,  // a call under way on generation_
    Stopped
  };

  // Starts the wanted call when it is due, and says when to wake.
  Orders next(Orders orders, Clock::time_point now);

  // What to say about a failed call, and the key that tells whether it was said already.
  LogLine failure(const std::string& message, const ServiceFound& found, std::string& key) const;

  SettingNames names_;
  std::string service_;
  std::string type_;
  std::string md5sum_;
  Clock::duration give_up_after_;
  Clock::duration retry_after_;
  Phase phase_ = Phase::Idle;
  bool wanted_ = false;   // a request not yet served by a call that started after it
  bool failing_ = false;  // the last call failed or was given up: retry on fresh connections
  std::string said_;      // while failing: the key of the failure said last ("": none said)
  Clock::time_point retry_at_ = Clock::time_point::min();
  // The call under way is given up then; none: waited for as long as it takes.
  std::optional<Clock::time_point> give_up_at_;
  std::uint64_t generation_ = 0;
  std::set<std::uint64_t> blocked_;  // generations given up whose threads have not ended
};

}  // namespace cartpole_qlearning
