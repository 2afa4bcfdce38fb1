// The message protocol between the simulator and the controller, both sides, without ROS.
// The nodes (cartpole_sim_node, qlearning_controller_node) feed these classes the messages
// they receive and carry out what the classes decide; this header is where the rules live.
//
// Identity. Every state the sim publishes carries a stamp (its sim time), and every command
// the controller publishes carries the stamp of the state it answers (joint_command,
// sensor_msgs/JointState, header.stamp). A stamp is the identity of a state, as actionlib's
// goal_id is the identity of a goal: a message whose stamp is not the one awaited is not taken
// for it, whatever the order in which messages arrive.
//
// The sim's side (SimProtocol), in lockstep:
//   - A new state (the first, after a step, after a reset) is one tick of sim time (tau) later
//     than the state before it, so time never goes back and no two states share a stamp. It
//     is the pending state until a command answers it.
//   - A command stamped with the pending state's stamp steps the physics (Step). Any other is
//     dropped and counted: Stale (an older state's, or one a reset replaced), Duplicate (a
//     second answer to the state just stepped on: the answer to a repeat whose first answer
//     also arrived), Future (a stamp the sim never published), Unstamped (stamp 0).
//   - An unstamped command (cart_effort, std_msgs/Float64: hand driving) answers whatever
//     state is pending.
//   - A state left unanswered for repeat_after (wall clock) is published again unchanged, same
//     stamp, and again after each further repeat_after: the state or its answer was lost (a
//     controller that subscribed late or restarted). Answering a repeat is always safe: at most
//     one command per stamp steps the sim.
//   - A reset makes a new pending state; an answer to the state before it, still in flight, is
//     then Stale.
// In realtime the sim steps on its wall timer and holds the last command (CommandHold).
//
// The controller's side (ControllerProtocol), in both clocks:
//   - A state with a stamp newer than the last one is new: it is judged by the task, learnt
//     from (the transition from the last state) and answered with the next action, stamped
//     with its stamp. Learning happens once per stamp, so a repeat never counts twice.
//   - A state with the last stamp is a repeat: answered again with the same effort and stamp
//     while the episode runs (its first answer may have been lost), ignored otherwise.
//   - A state older than the last one is dropped (a replayed or reordered message), unless the
//     same older stamp comes again (a sim that restarted publishes its first state, and
//     repeats it while nobody answers), or when three older states in a row each come newer
//     than the one before (time set back and going on: Gazebo's reset_simulation). Then the
//     running episode is abandoned without learning from its unfinished end, and the state is
//     taken as a start.
//   - Stamp 0 means "no stamp". A robot whose states all carry 0 is served, each message taken
//     as a new state (it cannot repeat or reorder anything); a 0 amid stamped states is a stray
//     and is dropped.
//   - An episode ends on the task's verdict (terminated or truncated). The controller learns
//     from the last transition (no bootstrap on a fall), then, with a reset service, asks for
//     a reset and waits for a new state that is not terminal (in realtime the sim goes on
//     stepping until the reset is served). Without one (a real robot), it commands zero and
//     starts the next episode on the first state inside the start region (a person stood the
//     pole up), learning nothing from the gap.
//   - A reset that failed (onResetOutcome: the call failed, or hung and was given up) left the
//     robot where it fell, and the reset caller retries it. Until a reset succeeds the robot is
//     served as one without a reset service: each new state answered with 0, and the next
//     episode started only on a state inside the start region, so that a spinning pole passing
//     upright is no episode. A repeat is not answered then (a lockstep sim waits on its fallen
//     state instead of stepping it on, flat out, for as long as no reset works). A
//     success puts the rule above back; the reset's first state may come before its answer or
//     after it: before it, it starts the episode when inside the start region, else it is
//     answered with 0 and the episode starts on the next state after the answer. With resets
//     that work, nothing of this happens: the normal path is as it was.
//   - A first state that is terminal (joining a sim that waits on a fallen pole) asks for a
//     reset without learning. So does a fallen state repeated twice after the reset asked for
//     came back done: the sim waits on a fall that is not the reset's start (something moved it
//     after the reset), and nothing else would answer it; and, from a realtime robot felled so,
//     50 new fallen states in a row.
//   - Training ends after the episode that reaches the limits (solved or max_episodes); every
//     state after it is ignored.
#pragma once

#include "cartpole_qlearning/simulation/cartpole_dynamics.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/common/setting_names.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
// Sim time in nanoseconds (ros::Time::toNSec() in the nodes); 0 means "no stamp".
using Stamp = std::uint64_t;
using WallClock = std::chrono::steady_clock;

// Sim time per step: tau rounded to whole nanoseconds, as ros::Duration(tau) rounds it.
// Throws std::invalid_argument when that is not at least 1 ns.
Stamp tickOf(double tau_s);

class SimProtocol
{
public:
  enum class Verdict
  {
    Step,       // answers the pending state: step the physics, then publish pending()
    Stale,      // answers an older state, or one that a reset replaced
    Duplicate,  // a second answer to the state the sim last stepped on
    Future,     // a stamp the sim has not published yet
    Unstamped   // stamp 0
  };

  struct Counts
  {
    std::uint64_t steps = 0;
    std::uint64_t resets = 0;
    std::uint64_t stale = 0;
    std::uint64_t duplicate = 0;
    std::uint64_t future = 0;
    std::uint64_t unstamped = 0;
    std::uint64_t repeats = 0;
  };

  // tick: sim time per step and per reset [ns] (tickOf); repeat_after: how long a state waits
  // unanswered (wall clock) before it is published again.
  SimProtocol(Stamp tick, WallClock::duration repeat_after);

  // The first state: sim time one tick after 0. Returns its stamp, now pending.
  Stamp start(WallClock::time_point now);
  // A stamped command (joint_command). On Step the next state is pending (pending()).
  Verdict onCommand(Stamp answers, WallClock::time_point now);
  // An unstamped command (cart_effort): always Step.
  Verdict onUnstampedCommand(WallClock::time_point now);
  // A reset (the service): a new state, one tick later, is pending. Returns its stamp.
  Stamp onReset(WallClock::time_point now);
  // A reset that sets time back to the first tick, as Gazebo's reset_simulation does (the sim
  // posing as such a robot; ~reset_simulation). Returns the new pending stamp.
  Stamp onResetTimeBack(WallClock::time_point now);
  // A timer tick: true when the pending state has waited repeat_after unanswered since it, or
  // its last repeat, was published: publish it again, unchanged.
  bool repeatDue(WallClock::time_point now);

  Stamp pending() const
  {
    return pending_;
  }
  const Counts& counts() const
  {
    return counts_;
  }

private:
  Stamp advance(WallClock::time_point now);

  Stamp tick_;
  WallClock::duration repeat_after_;
  Stamp pending_ = 0;
  Stamp last_stepped_ = 0;  // the stamp of the state the last Step answered (0: none yet)
  WallClock::time_point published_at_;
  Counts counts_;
};

// Why a verdict dropped a command, for the sim's warnings ("" for Step).
const char* describe(SimProtocol::Verdict verdict);

// Realtime: the zero-order hold of the last command. A command older than timeout counts as
// zero (turtlesim's command timeout); a stamped command older than the one held (reordered)
// is refused.
class CommandHold
{
public:
  explicit CommandHold(WallClock::duration timeout);
  // False (nothing changes) for a stamped command older than the one held.
  bool set(double effort, Stamp stamp, WallClock::time_point now);
  // The effort to apply now: the held one while fresh, else 0.
  double effort(WallClock::time_point now) const;

private:
  WallClock::duration timeout_;
  double effort_ = 0.0;
  Stamp stamp_ = 0;
  std::optional<WallClock::time_point> since_;
};

// What the controller does about one received state.
struct Reaction
{
  enum class Kind
  {
    New,      // a new state (learnt from when an episode ran)
    Repeat,   // the last state again
    Stale,    // older than the last state: dropped
    Stray,    // stamp 0 amid stamped states: dropped
    Finished  // training has ended: ignored
  };
  Kind kind = Kind::New;
  bool answer = false;  // publish a command: effort, stamped with stamp
  double effort = 0.0;
  Stamp stamp = 0;
  bool learned = false;              // a transition was learnt from (at most once per stamp)
  bool episode_began = false;        // this state starts an episode
  bool episode_ended = false;        // TrainingSession::lastEpisode() describes it
  bool training_finished = false;    // the episode just ended reached the training limits
  bool request_reset = false;        // call the sim's reset service
  bool waiting_for_start = false;    // no reset service: the episode ended, now commanding 0 until
                                     // the state is back in the start region (said once per gap)
  bool waiting_for_pole_up = false;  // ... until the pole is up (starts_when_up), not in the start region
  bool sim_restarted = false;        // time went back: the running episode was abandoned
  // Time went back (a stale state, or a restart) while the reset asked for was awaited: a reset
  // that sets time back (Gazebo's reset_simulation) does exactly that, every episode.
  bool awaiting_reset = false;
  bool clock_set_back = false;   // time went back with the pole up, and control went on
  bool first_unstamped = false;  // the first state of a stream without stamps (warn once)
};

struct ControllerProtocolParams
{
  bool reset_service = true;  // false: a robot that cannot be reset on command
  // A reset that does not say where it put the robot (std_srvs/Empty, Trigger): after it, the
  // episode starts only inside start_region, and until then states are answered with 0.
  bool reset_starts_in_region = false;
  // Without a reset service (or with one as above), an episode starts only when every
  // |state[i]| <= start_region[i].
  CartPoleState start_region = CartPoleState::Constant(0.05);
  // Training ends after the episode that reaches these (when learning).
  TrainingLimits limits;
  // Which of the session's robots this protocol serves (one protocol per robot).
  std::size_t robot = 0;
  // The robot's commands carry no stamp (std_msgs/Float64): a lockstep sim cannot tell the answer
  // to a repeat from the answer to its next state and steps on both, and from then on every
  // command lands a step late. A repeat of a state already answered is then answered only at
  // every kRepeatsBeforeAnsweringAgain-th repeat: the sim has waited that long, the answer was lost
  // (a connection not up yet), not late (a loaded machine answering after the sim's timeout).
  bool commands_unstamped = false;
  // Control (a table driving a robot, no learning): time going back is judged by the state, not
  // the clock. A pole still up goes on being balanced (a robot's clock stepped back, a sim
  // restarted at a start); only a fallen one waits for a start, as after any fall.
  bool time_back_judged_by_state = false;
  // A table run greedily on a robot without a reset service (evaluate, control): an episode starts
  // when the pole is up by the task's own thresholds (not terminal), not inside start_region,
  // which noisy readings of a balanced pole can miss for long; and an episode that ends at its
  // step limit with the pole up is followed at once by the next, answered as any state (an
  // upright pole is never left at zero between episodes). Training keeps start_region: its
  // episodes start where the task's starts are drawn.
  bool starts_when_up = false;
};

class ControllerProtocol
{
public:
  enum class Phase
  {
    WaitingForStart,   // no episode runs: the next usable new state starts one
    InEpisode,         // answering states, learning from each new one
    AwaitingReset,     // the episode ended and a reset was asked for
    WaitingForPerson,  // no reset service, or a failed reset: commanding 0 until the state is in
                       // the start region
    Finished           // training reached its limits
  };

  struct Counts
  {
    std::uint64_t states = 0;   // new states taken
    std::uint64_t repeats = 0;  // repeats received (answered or not)
    std::uint64_t stale = 0;
    std::uint64_t stray = 0;
    std::uint64_t restarts = 0;
    std::uint64_t resets_back = 0;  // of the restarts, those a requested reset made (awaiting_reset)
  };

  // The session is driven by this protocol (beginEpisode, observe, abortEpisode) and must
  // outlive it.
  ControllerProtocol(TrainingSession& session, const ControllerProtocolParams& params);

  Reaction onState(Stamp stamp, const CartPoleState& state);
  // A reset asked for (request_reset) came back: succeeded, or failed (not served, or given up);
  // the reset caller retries a failed one until it succeeds.
  void onResetOutcome(bool succeeded);
  // Whether onState would take a state with this stamp as new (and so may learn and draw from
  // the exploration stream). A learner serving several robots in rounds holds such a state
  // back until every robot has one; any other it passes on at once (a repeat is answered, a
  // stale state dropped, without touching the session).
  bool takesAsNew(Stamp stamp) const;

  Phase phase() const
  {
    return phase_;
  }
  const Counts& counts() const
  {
    return counts_;
  }

private:
  Reaction onNewState(Reaction reaction, const CartPoleState& state);
  void onEpisodeState(Reaction& reaction, const CartPoleState& state);
  void begin(Reaction& reaction, const CartPoleState& state);
  void answer(Reaction& reaction, double effort);
  // Asks for a reset and awaits its start.
  void requestReset(Reaction& reaction);
  // No reset to count on: begins on a state inside the start region, else commands 0.
  void waitForStartRegion(Reaction& reaction, const CartPoleState& state, bool terminal);
  bool inStartRegion(const CartPoleState& state) const;

  TrainingSession& session_;
  ControllerProtocolParams params_;
  Phase phase_ = Phase::WaitingForStart;
  bool have_stamp_ = false;  // a stamped (non-zero) state has been taken
  bool unstamped_stream_ = false;
  Stamp last_ = 0;
  std::optional<Stamp> older_seen_;  // an older stamp seen once: a restart if it comes again
  static constexpr int kTimeSetBack = 3;
  static constexpr int kRepeatsBeforeAnsweringAgain = 3;  // commands_unstamped
  std::optional<Stamp> answered_;                         // the stamp of the last state answered
  int repeats_held_back_ = 0;                             // repeats of it not answered (commands_unstamped)
  int older_run_ = 0;                                     // older states in a row, each newer than the one before
  double last_effort_ = 0.0;
  bool reset_failing_ = false;  // the last reset failed, none has succeeded since
  bool reset_served_ = false;   // AwaitingReset: the reset asked for came back done
  int fallen_repeats_ = 0;      // repeats of a fallen state since then
  // The state whose fall asked for the reset: its repeats are never a fall after the reset (a
  // controller busy at the episode's end, a whole verdict, finds several of them queued).
  std::optional<Stamp> reset_asked_by_;
  int fallen_states_ = 0;  // new fallen states since then
  static constexpr int kFallenStatesBeforeAskingAgain = 50;
  Counts counts_;
};

// What the controller says about a state that was not simply answered: robot names the robot
// (its joint_states topic), stamp_s is the state's stamp [s]. A dropped state and a restart are
// said only when dropped_ready() and restart_ready() (the node's throttles) allow it. names: how
// the front end names the start region.
LogLines reactionLog(const Reaction& reaction, const ControllerProtocol::Counts& counts, const std::string& robot,
                     double stamp_s, const std::function<bool()>& dropped_ready,
                     const std::function<bool()>& restart_ready, const SettingNames& names = {});

}  // namespace cartpole_qlearning
