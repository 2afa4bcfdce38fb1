#include "cartpole_qlearning/protocol/reset_calls.h"

#include <algorithm>
#include <cstdio>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
constexpr double kMinGiveUpS = 5.0;
constexpr double kMaxGiveUpS = 3600.0;

// now + d, or the end of time where that would overflow.
ResetCalls::Clock::time_point later(ResetCalls::Clock::time_point now, ResetCalls::Clock::duration d)
{
  return d >= ResetCalls::Clock::time_point::max() - now ? ResetCalls::Clock::time_point::max() : now + d;
}

}  // namespace

std::chrono::steady_clock::duration resetGiveUpAfter(double sim_timeout_s)
{
  // std::max keeps 5 s for a NaN.
  const double seconds = std::min(kMaxGiveUpS, std::max(kMinGiveUpS, 2.0 * sim_timeout_s));
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

ResetCalls::ResetCalls(std::string service, Clock::duration give_up_after, Clock::duration retry_after)
  : service_(std::move(service)), give_up_after_(give_up_after), retry_after_(retry_after)
{
}

ResetCalls::Orders ResetCalls::request(Clock::time_point now)
{
  if (phase_ == Phase::Stopped)
    return {};
  wanted_ = true;
  return next({}, now);
}

ResetCalls::Orders ResetCalls::onReturn(std::uint64_t generation, bool answered, const std::string& message,
                                        Clock::time_point now)
{
  if (blocked_.erase(generation) > 0 || phase_ != Phase::Calling || generation != generation_)
    return next({}, now);  // a given-up call back at last: only its slot is freed
  phase_ = Phase::Idle;
  give_up_at_.reset();
  Orders orders;
  if (answered)
  {
    if (failing_)
      orders.log.push_back({LogLine::Level::Info, service_ + " answers again; going on"});
    failing_ = false;
    return next(std::move(orders), now);
  }
  if (!failing_)
    orders.log.push_back({LogLine::Level::Warn, "reset call to " + service_ + " failed" +
                                                    (message.empty() ? "" : ": " + message) +
                                                    "; retrying until it answers"});
  failing_ = true;
  wanted_ = true;
  retry_at_ = later(now, retry_after_);
  return next(std::move(orders), now);
}

ResetCalls::Orders ResetCalls::onThreadEnded(std::uint64_t generation, Clock::time_point now)
{
  blocked_.erase(generation);
  return next({}, now);
}

ResetCalls::Orders ResetCalls::onTime(Clock::time_point now)
{
  if (phase_ != Phase::Calling || !give_up_at_ || now < *give_up_at_)
    return next({}, now);
  if (!blocked_.empty())
  {
    // Decided once, at the give-up time: a blocked call coming back later does not change it.
    give_up_at_.reset();
    return next({}, now);
  }
  Orders orders;
  orders.give_up = generation_;
  blocked_.insert(generation_++);
  phase_ = Phase::Idle;
  give_up_at_.reset();
  char after[32];
  std::snprintf(after, sizeof after, "%.1f", std::chrono::duration<double>(give_up_after_).count());
  orders.log.push_back({LogLine::Level::Warn, "reset call to " + service_ + " has not returned after " + after +
                                                  " s; giving it up and retrying on a new connection"});
  failing_ = true;
  wanted_ = true;
  retry_at_ = now;
  return next(std::move(orders), now);
}

ResetCalls::Orders ResetCalls::stop()
{
  Orders orders;
  if (phase_ == Phase::Calling)
  {
    orders.give_up = generation_;
    blocked_.insert(generation_++);
  }
  phase_ = Phase::Stopped;
  wanted_ = false;
  give_up_at_.reset();
  return orders;
}

ResetCalls::Orders ResetCalls::next(Orders orders, Clock::time_point now)
{
  if (phase_ == Phase::Idle && wanted_ && now >= retry_at_)
  {
    // Taken as the call starts: a request made while it is under way is served by the next one.
    wanted_ = false;
    phase_ = Phase::Calling;
    give_up_at_ = later(now, give_up_after_);
    orders.call = Call{generation_, !failing_};
  }
  if (phase_ == Phase::Calling && give_up_at_)
    orders.wake_at = *give_up_at_;
  else if (phase_ == Phase::Idle && wanted_)
    orders.wake_at = retry_at_;
  return orders;
}

}  // namespace cartpole_qlearning
