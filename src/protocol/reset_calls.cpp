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
constexpr std::chrono::seconds kOtherTypeRetryAfter(5);

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

const std::vector<std::string>& resetServiceTypes()
{
  static const std::vector<std::string> types{"cartpole_qlearning/Reset", "std_srvs/Empty", "std_srvs/Trigger"};
  return types;
}

ResetCalls::ResetCalls(std::string service, std::string type, std::string md5sum, Clock::duration give_up_after,
                       Clock::duration retry_after, SettingNames names)
  : names_(std::move(names)),
    service_(std::move(service)),
    type_(std::move(type)),
    md5sum_(std::move(md5sum)),
    give_up_after_(give_up_after),
    retry_after_(retry_after)
{
}

LogLine ResetCalls::failure(const std::string& message, const ServiceFound& found, std::string& key) const
{
  using Level = LogLine::Level;
  // What goes on while the calls fail: said with every failure, as it is the same for each.
  const std::string meanwhile =
      "; retrying until it answers, and until then an episode starts only when the state is inside " +
      names_(Setting::StartRegion);
  const std::string service_setting = names_(Setting::ResetService);
  const std::string type_setting = names_(Setting::ResetServiceType);
  if (found.kind == ServiceFound::Kind::Missing)
  {
    key = "missing";
    return {Level::Error, "reset service " + service_ + " is missing: no node advertises it. Start the node that " +
                              "serves it, or set " + service_setting +
                              " to the robot's reset service (\"\" for none: a " + "person stands the pole up)" +
                              meanwhile};
  }
  // "*" is what a server that takes any type answers (a relay): no type of its own to compare.
  const bool other_md5 = !found.md5sum.empty() && found.md5sum != "*" && found.md5sum != md5sum_;
  if (found.kind == ServiceFound::Kind::Served && (found.type != type_ || other_md5))
  {
    key = "serves " + found.type + " " + found.md5sum;
    std::string text = "reset service " + service_ + " serves " + found.type;
    if (found.type == type_)
      text += " of another definition than this controller's (md5sum " + found.md5sum + ", not " + md5sum_ +
              "): build both against the same " + type_;
    else if (std::find(resetServiceTypes().begin(), resetServiceTypes().end(), found.type) != resetServiceTypes().end())
      text += ", not " + type_ + " as " + type_setting + " asks: set " + type_setting + " to " + found.type;
    else
      text += ", not " + type_ + " as " + type_setting + " asks, and " + type_setting + " can only be " +
              "cartpole_qlearning/Reset, std_srvs/Empty or std_srvs/Trigger: set " + service_setting +
              " to a service of " + "one of these (\"\" for none: a person stands the pole up)";
    return {Level::Error, text + meanwhile};
  }
  key = "failed";
  return {Level::Warn, "reset call to " + service_ + " failed" + (message.empty() ? "" : ": " + message) + meanwhile};
}

ResetCalls::Orders ResetCalls::request(Clock::time_point now)
{
  if (phase_ == Phase::Stopped)
    return {};
  wanted_ = true;
  return next({}, now);
}

ResetCalls::Orders ResetCalls::onReturn(std::uint64_t generation, bool answered, const std::string& message,
                                        Clock::time_point now, const ServiceFound& found)
{
  if (blocked_.erase(generation) > 0 || phase_ != Phase::Calling || generation != generation_)
    return next({}, now);  // a given-up call back at last: only its slot is freed
  phase_ = Phase::Idle;
  give_up_at_.reset();
  Orders orders;
  orders.reset_done = answered;
  if (answered)
  {
    if (failing_)
      orders.log.push_back({LogLine::Level::Info, service_ + " answers again; going on"});
    failing_ = false;
    said_.clear();
    return next(std::move(orders), now);
  }
  // Said once while the calls fail, and again when what the service turned out to be changes.
  std::string key;
  LogLine line = failure(message, found, key);
  if (key != said_)
    orders.log.push_back(std::move(line));
  said_ = key;
  failing_ = true;
  wanted_ = true;
  // A service of another type stays so until someone changes a node: retried less often, as each
  // call makes its server log an error of its own (roscpp's md5sum mismatch).
  const bool other_type = found.kind == ServiceFound::Kind::Served && key != "failed";
  retry_at_ = later(now, other_type ? std::max<Clock::duration>(retry_after_, kOtherTypeRetryAfter) : retry_after_);
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
  orders.reset_done = false;
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
