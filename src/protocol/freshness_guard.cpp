#include "cartpole_qlearning/protocol/freshness_guard.h"

#include <algorithm>
#include <chrono>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
double seconds(WallClock::duration d)
{
  return std::chrono::duration<double>(d).count();
}

// A first publisher silent this long (or the guard's bound, when longer) has gone: a publisher
// that comes after it takes over (a driver restarted under a new anonymous name, which takes
// seconds to start anyway). Four times a lockstep sim's repeat (sim.yaml's lockstep_timeout,
// 0.5 s): a sim whose answer was lost is silent that long before it repeats, and a stray
// publisher must not take its place then (bad_messages.test's flood did, and training stalled).
constexpr WallClock::duration kPublisherGone = std::chrono::seconds(2);
constexpr WallClock::duration kSayStopEvery = std::chrono::seconds(10);
}  // namespace

const char* describe(FreshnessGuard::Cause cause)
{
  switch (cause)
  {
    case FreshnessGuard::Cause::Silence:
      return "silence";
    case FreshnessGuard::Cause::SecondDriver:
      return "a second driver";
    case FreshnessGuard::Cause::Invalid:
      return "invalid states";
    case FreshnessGuard::Cause::Unstamped:
      return "unstamped states";
    case FreshnessGuard::Cause::Frozen:
      return "frozen stamps";
    case FreshnessGuard::Cause::Older:
      return "older stamps";
  }
  return "?";
}

FreshnessGuard::FreshnessGuard(WallClock::duration bound, std::string robot)
  : bound_(std::max(bound, WallClock::duration::zero())), robot_(std::move(robot))
{
}

bool FreshnessGuard::onMessage(Stamp stamp, bool valid, const std::string& publisher, WallClock::time_point now,
                               LogLines& log)
{
  // Off, off entirely: a lockstep sim's stamps already keep a stray publisher's states from
  // being taken for the sim's (lockstep_protocol.h), and no publisher is refused.
  if (!enabled())
    return true;
  if (!publisher.empty())
  {
    const bool first_gone = now - publisher_heard_at_ > std::max(bound_, kPublisherGone);
    if (publisher_.empty() || (publisher != publisher_ && first_gone))
    {
      if (!publisher_.empty())
        log.push_back({LogLine::Level::Info, formatText("joint_states on %s now come from %s (%s has gone silent)",
                                                        robot_.c_str(), publisher.c_str(), publisher_.c_str())});
      publisher_ = publisher;
      refused_publisher_.clear();
    }
    if (publisher != publisher_)
    {
      ++since_decision_[static_cast<int>(Cause::SecondDriver)];
      last_cause_ = Cause::SecondDriver;
      if (refused_publisher_ != publisher)
      {
        refused_publisher_ = publisher;
        log.push_back(
            {LogLine::Level::Error,
             formatText("joint_states on %s come from two publishers, %s and %s: two drivers of one robot? "
                        "Only %s's states are taken; stop %s",
                        robot_.c_str(), publisher_.c_str(), publisher.c_str(), publisher_.c_str(), publisher.c_str())});
      }
      return false;
    }
    publisher_heard_at_ = now;
  }
  std::optional<Cause> cause;
  if (!valid)
    cause = Cause::Invalid;
  else if (stamp == 0 && stamped_)
    cause = Cause::Unstamped;
  else if (stamp != 0 && last_decided_ && stamp == *last_decided_)
    cause = Cause::Frozen;
  else if (stamp != 0 && last_decided_ && stamp < *last_decided_)
    cause = Cause::Older;
  if (cause)
  {
    ++since_decision_[static_cast<int>(*cause)];
    last_cause_ = cause;
  }
  else
    ++fresh_since_decision_;
  return true;
}

void FreshnessGuard::onDecision(Stamp stamp, WallClock::time_point now, LogLines& log)
{
  if (stopped_ && stop_said_)
    log.push_back({LogLine::Level::Info,
                   formatText("fresh joint_states on %s again after %.2f s without; deciding again", robot_.c_str(),
                              last_decision_at_ ? seconds(now - *last_decision_at_) : 0.0)});
  stopped_ = false;
  last_decision_at_ = now;
  last_decided_ = stamp;
  stamped_ = stamped_ || stamp != 0;
  std::fill(std::begin(since_decision_), std::end(since_decision_), 0);
  fresh_since_decision_ = 0;
  last_cause_.reset();
}

bool FreshnessGuard::stale(WallClock::time_point now) const
{
  return enabled() && last_decision_at_ && now - *last_decision_at_ > bound_;
}

bool FreshnessGuard::check(WallClock::time_point now, LogLines& log)
{
  if (stopped_ || !stale(now))
    return false;
  stopped_ = true;
  std::optional<WallClock::time_point>& said_at = stop_said_at_[static_cast<int>(cause())];
  stop_said_ = !said_at || now - *said_at >= kSayStopEvery;
  if (stop_said_)
  {
    said_at = now;
    log.push_back({LogLine::Level::Warn, describeStop(now)});
  }
  return true;
}

bool FreshnessGuard::mayPush(WallClock::time_point now) const
{
  return !stale(now) && !stopped_;
}

FreshnessGuard::Cause FreshnessGuard::cause() const
{
  return last_cause_ ? *last_cause_ : Cause::Silence;
}

std::string FreshnessGuard::describeStop(WallClock::time_point now) const
{
  const double without = last_decision_at_ ? seconds(now - *last_decision_at_) : 0.0;
  const std::uint64_t count = since_decision_[static_cast<int>(cause())];
  const double last_s = last_decided_ ? static_cast<double>(*last_decided_) * 1e-9 : 0.0;
  std::string why;
  switch (cause())
  {
    case Cause::Silence:
      why = fresh_since_decision_ == 0
                ? std::string("no joint_states at all: is the robot's driver running?")
                : formatText(
                      "%llu fresh joint_states came and none was decided on: the controller is waiting, for "
                      "a reset, for the pole to come up or for the other robots of a round",
                      static_cast<unsigned long long>(fresh_since_decision_));
      break;
    case Cause::SecondDriver:
      why = formatText("%llu from a second publisher, refused", static_cast<unsigned long long>(count));
      break;
    case Cause::Invalid:
      why = formatText("%llu with NaN or inf readings or a joint missing", static_cast<unsigned long long>(count));
      break;
    case Cause::Unstamped:
      why = formatText("%llu without a stamp (0) after stamped ones", static_cast<unsigned long long>(count));
      break;
    case Cause::Frozen:
      why = formatText(
          "%llu with the stamp already decided on, %.3f s: frozen stamps (a driver republishing "
          "its last message?)",
          static_cast<unsigned long long>(count), last_s);
      break;
    case Cause::Older:
      why = formatText("%llu with stamps older than %.3f s, the last decided on (time went back, or a replay)",
                       static_cast<unsigned long long>(count), last_s);
      break;
  }
  return formatText("no fresh state on %s for %.2f s (%s; the bound is %.2f s): commanding 0 until a fresh one comes",
                    robot_.c_str(), without, why.c_str(), seconds(bound_));
}

}  // namespace cartpole_qlearning
