#include "cartpole_qlearning/protocol/lockstep_protocol.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
Stamp tickOf(double tau_s)
{
  const double ns = std::round(tau_s * 1e9);
  if (!(std::isfinite(ns) && ns >= 1.0 && ns < 1e18))
    throw std::invalid_argument("tau = " + std::to_string(tau_s) + " s is not a usable tick (at least 1 ns)");
  return static_cast<Stamp>(ns);
}

// --- The sim's side ---------------------------------------------------------------------------

SimProtocol::SimProtocol(Stamp tick, WallClock::duration repeat_after) : tick_(tick), repeat_after_(repeat_after)
{
  if (tick_ == 0)
    throw std::invalid_argument("SimProtocol: the tick must be at least 1 ns");
}

Stamp SimProtocol::advance(WallClock::time_point now)
{
  pending_ += tick_;
  published_at_ = now;
  return pending_;
}

Stamp SimProtocol::start(WallClock::time_point now)
{
  pending_ = 0;
  last_stepped_ = 0;
  return advance(now);
}

SimProtocol::Verdict SimProtocol::onCommand(Stamp answers, WallClock::time_point now)
{
  if (answers == 0)
  {
    ++counts_.unstamped;
    return Verdict::Unstamped;
  }
  if (answers == pending_)
    return onUnstampedCommand(now);
  if (answers == last_stepped_)
  {
    ++counts_.duplicate;
    return Verdict::Duplicate;
  }
  if (answers < pending_)
  {
    ++counts_.stale;
    return Verdict::Stale;
  }
  ++counts_.future;
  return Verdict::Future;
}

SimProtocol::Verdict SimProtocol::onUnstampedCommand(WallClock::time_point now)
{
  last_stepped_ = pending_;
  ++counts_.steps;
  advance(now);
  return Verdict::Step;
}

Stamp SimProtocol::onReset(WallClock::time_point now)
{
  ++counts_.resets;
  return advance(now);
}

Stamp SimProtocol::onResetTimeBack(WallClock::time_point now)
{
  ++counts_.resets;
  return start(now);
}

bool SimProtocol::repeatDue(WallClock::time_point now)
{
  if (now - published_at_ < repeat_after_)
    return false;
  published_at_ = now;
  ++counts_.repeats;
  return true;
}

const char* describe(SimProtocol::Verdict verdict)
{
  switch (verdict)
  {
    case SimProtocol::Verdict::Step:
      return "";
    case SimProtocol::Verdict::Stale:
      return "it answers an older state (or one a reset replaced)";
    case SimProtocol::Verdict::Duplicate:
      return "it is a second answer to a state already stepped on";
    case SimProtocol::Verdict::Future:
      return "its stamp is later than any state published";
    case SimProtocol::Verdict::Unstamped:
      return "it has no stamp (stamp it with the state's stamp, or publish on cart_effort)";
  }
  return "";
}

CommandHold::CommandHold(WallClock::duration timeout) : timeout_(timeout) {}

bool CommandHold::set(double effort, Stamp stamp, WallClock::time_point now)
{
  if (stamp != 0 && stamp < stamp_)
    return false;
  if (stamp != 0)
    stamp_ = stamp;
  effort_ = effort;
  since_ = now;
  return true;
}

double CommandHold::effort(WallClock::time_point now) const
{
  return since_ && now - *since_ <= timeout_ ? effort_ : 0.0;
}

// --- The controller's side --------------------------------------------------------------------

ControllerProtocol::ControllerProtocol(TrainingSession& session, const ControllerProtocolParams& params)
  : session_(session), params_(params)
{
}

bool ControllerProtocol::inStartRegion(const CartPoleState& state) const
{
  return (state.array().abs() <= params_.start_region.array()).all();
}

void ControllerProtocol::answer(Reaction& reaction, double effort)
{
  reaction.answer = true;
  reaction.effort = effort;
  last_effort_ = effort;
  answered_ = reaction.stamp;
}

void ControllerProtocol::begin(Reaction& reaction, const CartPoleState& state)
{
  reaction.episode_began = true;
  phase_ = Phase::InEpisode;
  answer(reaction, session_.beginEpisode(state, params_.robot));
}

void ControllerProtocol::waitForStartRegion(Reaction& reaction, const CartPoleState& state, bool terminal)
{
  if (!terminal && (params_.starts_when_up || inStartRegion(state)))
  {
    begin(reaction, state);
    return;
  }
  // Said for a robot without a reset service; a failing reset is said by the reset caller.
  reaction.waiting_for_start = !params_.reset_service && phase_ != Phase::WaitingForPerson;
  reaction.waiting_for_pole_up = params_.starts_when_up;
  phase_ = Phase::WaitingForPerson;
  answer(reaction, 0.0);
}

void ControllerProtocol::onResetOutcome(bool succeeded)
{
  if (!params_.reset_service)
    return;
  reset_failing_ = !succeeded;
  if (!succeeded && phase_ == Phase::AwaitingReset)
  {
    // The robot stays where it fell: its new states are answered with 0 from now on.
    phase_ = Phase::WaitingForPerson;
    last_effort_ = 0.0;
  }
  else if (succeeded && phase_ == Phase::WaitingForPerson)
    phase_ = Phase::AwaitingReset;  // the next state that is not fallen is the reset's start
  reset_served_ = succeeded && phase_ == Phase::AwaitingReset;
  fallen_repeats_ = 0;
  fallen_states_ = 0;
}

bool ControllerProtocol::takesAsNew(Stamp stamp) const
{
  if (phase_ == Phase::Finished)
    return false;
  if (stamp == 0)
    return !have_stamp_;
  if (have_stamp_ && stamp == last_)
    return false;
  if (have_stamp_ && stamp < last_)
    return older_seen_ == stamp;
  return true;
}

Reaction ControllerProtocol::onState(Stamp stamp, const CartPoleState& state)
{
  Reaction reaction;
  reaction.stamp = stamp;
  if (phase_ == Phase::Finished)
  {
    reaction.kind = Reaction::Kind::Finished;
    return reaction;
  }

  if (stamp == 0)
  {
    if (have_stamp_)
    {
      ++counts_.stray;
      reaction.kind = Reaction::Kind::Stray;
      return reaction;
    }
    reaction.first_unstamped = !unstamped_stream_;
    unstamped_stream_ = true;
    return onNewState(reaction, state);
  }

  if (have_stamp_ && stamp == last_)
  {
    ++counts_.repeats;
    reaction.kind = Reaction::Kind::Repeat;
    // The reset asked for was served, yet a lockstep sim waits on a fallen state: something moved
    // it after the reset (a hand on cart_effort, a stray command) and the reset's start was never
    // seen. Nothing would answer it; ask again. The second repeat, not the first: a repeat of the
    // fall sent before the reset may still be in flight. Never the fall that asked for the reset:
    // the sim repeated it until the reset came, every repeat_after, and a controller that took
    // long over the episode's end (a whole verdict on a loaded machine) reads them all after the
    // reset's answer. Asking again there reset the sim twice, and lockstep training was no
    // longer train_headless's.
    if (phase_ == Phase::AwaitingReset && reset_served_ && stamp != reset_asked_by_ &&
        session_.task().isTerminal(state) && !inStartRegion(state) && ++fallen_repeats_ >= 2)
    {
      requestReset(reaction);
      return reaction;
    }
    // Not while a failed reset is waited on: the fallen state a lockstep sim repeats was never
    // answered, and answering it would step the sim on, flat out, for as long as no reset works.
    if (!(phase_ == Phase::InEpisode || (phase_ == Phase::WaitingForPerson && !reset_failing_)))
      return reaction;
    if (params_.commands_unstamped && answered_ == stamp && ++repeats_held_back_ < kRepeatsBeforeAnsweringAgain)
      return reaction;
    repeats_held_back_ = 0;
    answer(reaction, last_effort_);
    return reaction;
  }

  if (have_stamp_ && stamp < last_)
  {
    // Time going on from an older stamp for kTimeSetBack states (Gazebo's reset_simulation sets
    // time back) is a restart too; fewer are replayed or reordered messages.
    older_run_ = older_seen_ && stamp > *older_seen_ ? older_run_ + 1 : 1;
    reaction.awaiting_reset = phase_ == Phase::AwaitingReset;
    if (older_seen_ != stamp && older_run_ < kTimeSetBack)
    {
      older_seen_ = stamp;
      ++counts_.stale;
      reaction.kind = Reaction::Kind::Stale;
      return reaction;
    }
    // The same older state twice (a restarted sim repeating its first state), or time set back.
    ++counts_.restarts;
    counts_.resets_back += reaction.awaiting_reset ? 1 : 0;
    if (params_.time_back_judged_by_state && phase_ == Phase::InEpisode && !session_.task().isTerminal(state))
    {
      reaction.clock_set_back = true;
    }
    else
    {
      reaction.sim_restarted = true;
      session_.abortEpisode(params_.robot);
      phase_ = Phase::WaitingForStart;
    }
  }
  return onNewState(reaction, state);
}

void ControllerProtocol::requestReset(Reaction& reaction)
{
  reaction.request_reset = true;
  reset_asked_by_ = reaction.stamp;
  phase_ = Phase::AwaitingReset;
  reset_served_ = false;
  fallen_repeats_ = 0;
  fallen_states_ = 0;
}

// A state of the running episode: decided on and learnt from; at the episode's end, what comes
// next (the training's end, a reset, the next episode at once, or a wait for a start).
void ControllerProtocol::onEpisodeState(Reaction& reaction, const CartPoleState& state)
{
  const Decision decision = session_.observe(state, params_.robot);
  reaction.learned = session_.learning();
  if (!decision.episode_over)
  {
    answer(reaction, decision.effort);
    return;
  }
  reaction.episode_ended = true;
  const EpisodeSummary& summary = session_.lastEpisode();
  if (session_.learning() && params_.limits.reached(summary.episode, summary.solved))
  {
    reaction.training_finished = true;
    phase_ = Phase::Finished;
    return;
  }
  if (params_.reset_service)
  {
    requestReset(reaction);
    return;
  }
  if (params_.starts_when_up && !session_.task().isTerminal(state))
  {
    begin(reaction, state);  // the step limit, the pole up: the next episode goes on from here
    return;
  }
  reaction.waiting_for_start = true;
  reaction.waiting_for_pole_up = params_.starts_when_up;
  phase_ = Phase::WaitingForPerson;
  answer(reaction, 0.0);
}

Reaction ControllerProtocol::onNewState(Reaction reaction, const CartPoleState& state)
{
  reaction.kind = Reaction::Kind::New;
  ++counts_.states;
  repeats_held_back_ = 0;
  fallen_repeats_ = 0;
  older_seen_.reset();
  older_run_ = 0;
  if (reaction.stamp != 0)
  {
    last_ = reaction.stamp;
    have_stamp_ = true;
  }
  const bool terminal = session_.task().isTerminal(state);

  switch (phase_)
  {
    case Phase::Finished:
      break;
    case Phase::AwaitingReset:
      if (reset_failing_)
      {
        waitForStartRegion(reaction, state, terminal);
        break;
      }
      // States that come before the reset is served (realtime) are past the fall. A start drawn
      // past the fall (a start region wider than the fall's 12 degrees: config/robust.yaml's) is
      // an episode of one step, as train_headless has it; without this the lockstep sim would
      // wait on it for ever. The fallen states of a realtime sim still falling before its reset
      // is served lie outside such a region but for the rare one falling slowly near its edge.
      if (params_.reset_starts_in_region ? !terminal && inStartRegion(state) : !terminal || inStartRegion(state))
        begin(reaction, state);
      // A realtime robot felled after its reset was served (the start never seen) sends new
      // fallen states, not repeats: after a second's worth at 50 Hz (far more than can still be
      // in flight from before the reset), ask again.
      else if (reset_served_ && terminal && !inStartRegion(state) && ++fallen_states_ >= kFallenStatesBeforeAskingAgain)
        requestReset(reaction);
      else if (params_.reset_starts_in_region)
        answer(reaction, 0.0);
      break;
    case Phase::WaitingForStart:
    case Phase::WaitingForPerson:
      if (!params_.reset_service || reset_failing_)
      {
        waitForStartRegion(reaction, state, terminal);
        break;
      }
      if (terminal && !inStartRegion(state))
      {
        // Joining a sim that waits on a fallen pole: nothing to learn from, ask for a start.
        requestReset(reaction);
        break;
      }
      begin(reaction, state);
      break;
    case Phase::InEpisode:
      onEpisodeState(reaction, state);
      break;
  }
  return reaction;
}

LogLines reactionLog(const Reaction& reaction, const ControllerProtocol::Counts& c, const std::string& robot,
                     double stamp_s, const std::function<bool()>& dropped_ready,
                     const std::function<bool()>& restart_ready, const SettingNames& names)
{
  using Level = LogLine::Level;
  const auto count = [](std::uint64_t n) { return static_cast<unsigned long long>(n); };
  LogLines log;
  // A reset asked for that sets time back: its first states look older, and then time goes on
  // from there. Said once, as what it is; every episode would otherwise warn twice.
  if (reaction.awaiting_reset && reaction.sim_restarted && c.resets_back == 1)
    log.push_back({Level::Info, formatText("%s: the reset set time back to %.3f s (as Gazebo's reset_simulation "
                                           "does): each reset's start is taken from where time goes on (said once)",
                                           robot.c_str(), stamp_s)});
  if (reaction.kind == Reaction::Kind::Stale && !reaction.awaiting_reset && dropped_ready())
    log.push_back(
        {Level::Warn, formatText("dropped joint_states on %s stamped %.6f, older than the last state (a "
                                 "replayed or reordered message; a restarted sim is recognised when it "
                                 "sends its state again, time set back when it goes on). Dropped so far: %llu",
                                 robot.c_str(), stamp_s, count(c.stale))});
  if (reaction.kind == Reaction::Kind::Stray && dropped_ready())
    log.push_back({Level::Warn, formatText("dropped joint_states on %s without a stamp among stamped ones. Dropped so "
                                           "far: %llu",
                                           robot.c_str(), count(c.stray))});
  if (reaction.first_unstamped)
    log.push_back({Level::Warn, formatText("joint_states on %s carry no stamp (0): every message is taken as a new "
                                           "state, and commands go out unstamped",
                                           robot.c_str())});
  if (reaction.sim_restarted && !reaction.awaiting_reset && restart_ready())
    log.push_back({Level::Warn, formatText("%s: time went back to %.3f s: the sim restarted (or was reset); starting "
                                           "a new episode. Restarts so far: %llu",
                                           robot.c_str(), stamp_s, count(c.restarts))});
  if (reaction.clock_set_back && restart_ready())
    log.push_back({Level::Warn, formatText("%s: time went back to %.3f s while the pole was up (the robot's clock was "
                                           "set back, or its driver restarted): balancing goes on. Times so far: %llu",
                                           robot.c_str(), stamp_s, count(c.restarts))});
  if (reaction.waiting_for_start)
    log.push_back(
        {Level::Info,
         reaction.waiting_for_pole_up
             ? formatText("%s: the pole is down and there is no reset service: commanding 0 until it is back up "
                          "(inside the task's thresholds): someone has to stand it up",
                          robot.c_str())
             : formatText("%s: episode over; no reset service, so commanding 0 until the state is back inside "
                          "%s (stand the pole up)",
                          robot.c_str(), names(Setting::StartRegion).c_str())});
  return log;
}

}  // namespace cartpole_qlearning
