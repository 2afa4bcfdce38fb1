// The freshness guard: a robot is never left pushed by a controller that cannot see it.
//
// A robot holds the last command it got (ros_control's forward controllers hold it for ever; our
// sim in real time for its command_timeout). A controller may only leave an effort on it while it
// decides from fresh, valid states: a stamp newer than the last one decided on, finite values,
// both joints. Whatever else arrives keeps nothing alive: a driver republishing its last cached
// message (frozen stamps), stamps that drop to 0 among stamped ones, NaN or inf readings, a
// missing joint, stamps that went back, a second publisher on the same topic, or nothing at all.
// When no fresh state has been decided on for `bound` (wall clock), the controller commands 0 and
// goes on commanding 0 in place of every effort until a fresh state is decided on again; it says
// once, when that happens, why (what arrived instead), and once when fresh states are back.
//
// One guard per robot. The node feeds it every message (onMessage), every decision (onDecision)
// and its timer (check), and asks it before it publishes an effort (mayPush). A bound of zero
// turns the guard off: a lockstep sim holds no command (it steps once per answer), and answering
// its repeats as they are keeps a run reproducible.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <cstdint>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
class FreshnessGuard
{
public:
  // What arrived instead of a fresh state, from the likeliest cause of a stop to the least.
  enum class Cause
  {
    Silence,       // nothing
    SecondDriver,  // states from a second publisher while the first is alive
    Invalid,       // NaN or inf readings, a missing joint
    Unstamped,     // stamp 0 after stamped states
    Frozen,        // the stamp last decided on, again and again
    Older          // stamps older than the last decided on
  };

  // robot: the robot's name in what is said (its joint_states topic).
  FreshnessGuard(WallClock::duration bound, std::string robot);

  // Every joint_states message, before anything decides on it. valid: finite readings and both
  // joints found. publisher: the caller id of the node that published it ("" when unknown).
  // Returns false when the message must be dropped: it comes from a second publisher while the
  // first one is alive (said once, as an error naming both).
  bool onMessage(Stamp stamp, bool valid, const std::string& publisher, WallClock::time_point now, LogLines& log);
  // The controller decided on a fresh state (a new stamp taken). Says when this ends a stop.
  void onDecision(Stamp stamp, WallClock::time_point now, LogLines& log);
  // The timer: true once when the bound has passed without a fresh decision and the controller
  // must command 0 now (said once, with the cause).
  bool check(WallClock::time_point now, LogLines& log);
  // Whether an effort other than 0 may go out now (a decision, a hold between decisions, the
  // answer to a repeat); false: publish 0 in its place.
  bool mayPush(WallClock::time_point now) const;

  bool enabled() const
  {
    return bound_ > WallClock::duration::zero();
  }
  bool stopped() const
  {
    return stopped_;
  }
  // What keeps fresh states away now (meaningful while stopped()).
  Cause cause() const;

private:
  bool stale(WallClock::time_point now) const;
  std::string describeStop(WallClock::time_point now) const;

  WallClock::duration bound_;
  std::string robot_;
  std::optional<WallClock::time_point> last_decision_at_;
  std::optional<Stamp> last_decided_;
  bool stamped_ = false;  // a stamped (non-zero) state has been decided on
  bool stopped_ = false;
  // What arrived since the last decision, by cause (Silence is never counted).
  static constexpr int kCauses = static_cast<int>(Cause::Older) + 1;
  std::uint64_t since_decision_[kCauses] = {};
  std::optional<Cause> last_cause_;
  // Fresh states (none of the causes above) since the last decision, none decided on: a silence
  // with these is the controller waiting (a reset, the pole to come up, a round), not the robot.
  std::uint64_t fresh_since_decision_ = 0;
  // The publisher whose states are taken, and when it was last heard.
  std::string publisher_;
  WallClock::time_point publisher_heard_at_;
  std::string refused_publisher_;  // the second one, said once
  // A robot whose states come and go (a loaded machine in real time) is stopped each time, but
  // said so at most once per kSayStopEvery for each cause; its return is said when its stop was.
  // Per cause, so that a hiccup of silence never hides a new misbehaviour (stamps dropping to 0
  // a second later) from the log.
  std::optional<WallClock::time_point> stop_said_at_[kCauses];
  bool stop_said_ = false;
};

const char* describe(FreshnessGuard::Cause cause);

}  // namespace cartpole_qlearning
