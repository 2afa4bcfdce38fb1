// Which robot's state a learner serving one robot or several decides on, and when: the learner
// node's policy between its joint_states callbacks and each robot's ControllerProtocol. Per
// robot it maps the readings to the task's state (StateMapping), decides at most once per
// ~decision_period (DecisionClock; the states between are answered with the effort held, except
// a fall, which ends the episode whenever it comes), and holds a new state back for its round
// (RobotRounds) so that the Q-table depends on the seed alone. A robot silent for ~sim_timeout is
// reported once and commanded zero, and drops out of the rounds while the others wait. Each
// robot's FreshnessGuard keeps its efforts going only while fresh, valid states are decided on
// (freshness_timeout_s): frozen or dropping stamps, invalid readings, a second publisher or
// silence command it zero within the bound.
//
// Events in (a state arrived, a timer tick), orders out: the node feeds it what it receives with
// the time, then serves each Turn that next() returns (publishes, ends episodes, asks for resets)
// until there is none or the run is over. Every line it says is in the returned LogLines.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/common/wall_throttle.h"
#include "cartpole_qlearning/learning/training_session.h"
#include "cartpole_qlearning/protocol/freshness_guard.h"
#include "cartpole_qlearning/protocol/lockstep_protocol.h"
#include "cartpole_qlearning/protocol/robot_interface.h"
#include "cartpole_qlearning/protocol/robot_rounds.h"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
struct RobotDispatchParams
{
  // How the log names each robot (the node: its joint_states topic); one per robot of the session.
  std::vector<std::string> robots;
  bool sync = true;                   // ~sync: several robots' new states in rounds
  double silent_after_s = 5.0;        // ~sim_timeout [s]: a robot this long without a state is silent
  double freshness_timeout_s = 0.0;   // ~freshness_timeout [s]: efforts only this long after a fresh state (0: off)
  RobotInterfaceParams robot;         // the readings' mapping and ~decision_period (every robot alike)
  ControllerProtocolParams protocol;  // every robot's (the index is set per robot)
  // The robots are cartpole_sims (their reset service is a cartpole_sim's): what the silence
  // warning asks about; else a robot's driver.
  bool simulated = true;
  SettingNames names;  // how the front end names the settings the warnings point at
};

class RobotDispatch
{
public:
  // What the node carries out after an event, besides serving next().
  struct Orders
  {
    LogLines log;
    // onState: the state is not decided on (within the decision period): answer it with the
    // effort held, stamped with its stamp (with 0 when hold_zero: the guard allows no effort).
    bool hold = false;
    bool hold_zero = false;
    // onState, onInvalid: the message is dropped (a second publisher's, or invalid readings).
    bool drop = false;
    // onTick: robots silent for silent_after_s, or whose guard has just stopped them: command them zero.
    std::vector<std::size_t> stop;
  };

  // One state served: the robot's ControllerProtocol has reacted; the node carries the reaction
  // out (answer, episode end, reset) after logging `log` (reactionLog's lines).
  struct Turn
  {
    std::size_t robot = 0;
    Stamp stamp = 0;
    CartPoleState state = CartPoleState::Zero();  // the state served, as the table sees it
    Reaction reaction;
    LogLines log;
  };

  // The session is driven by the robots' protocols and must outlive this. now: the start of
  // every robot's silence.
  RobotDispatch(TrainingSession& session, const RobotDispatchParams& params, WallClock::time_point now);

  // A state of `robot` arrived, stamped `stamp`, at wall time now, from `publisher` (its caller
  // id; "" when unknown).
  Orders onState(std::size_t robot, Stamp stamp, const JointReadings& readings, WallClock::time_point now,
                 const std::string& publisher = "");
  // A message of `robot` without a usable state (NaN or inf readings, a joint missing): the node
  // has dropped it and said why; the guard counts it.
  Orders onInvalid(std::size_t robot, Stamp stamp, WallClock::time_point now, const std::string& publisher = "");
  // The watchdog's tick: silent robots (reported once each until heard again) and drop-outs.
  Orders onTick(WallClock::time_point now);
  // A reset of `robot` asked for by a Turn's request_reset came back: succeeded or failed (its
  // ResetCalls' reset_done). Fed before the states that arrive after it.
  void onResetOutcome(std::size_t robot, bool succeeded);
  // The next state to serve, or none: a state taken at once, else every state of a complete
  // round, in robot order. Call until none (or until the run is over) after every event.
  std::optional<Turn> next(WallClock::time_point now);

  // How often onTick must come: the silence report within half of silent_after_s, and the guard's
  // stop within a quarter of its bound past it.
  double tickSeconds() const;

  const ControllerProtocol& protocol(std::size_t robot) const
  {
    return robots_.at(robot).protocol;
  }

private:
  struct Robot
  {
    Robot(TrainingSession& session, const RobotDispatchParams& params, std::size_t index);
    std::string name;
    ControllerProtocol protocol;
    StateMapping mapping;
    DecisionClock decisions;
    FreshnessGuard guard;
    Stamp held_stamp = 0;  // a new state waiting for its round
    CartPoleState held_state;
    bool silent_reported = false;
    // The last message of any kind, valid or not: a driver that publishes only what cannot be
    // used (NaN, its joints missing) is not silent, and the warning says so.
    std::optional<WallClock::time_point> last_message;
  };
  struct Waiting
  {
    std::size_t robot;
    Stamp stamp;
    CartPoleState state;
  };

  Turn serve(std::size_t robot, Stamp stamp, const CartPoleState& state, WallClock::time_point now);

  TrainingSession& session_;
  RobotDispatchParams params_;
  std::vector<Robot> robots_;
  RobotRounds rounds_;
  std::optional<Waiting> at_once_;  // a state not held for a round, served by the next next()
  bool in_round_ = false;           // a complete round is being served
  WallThrottle slow_states_warning_{10.0};
  WallThrottle dropped_state_warning_{1.0};
  // A replayed older stamp, sent twice, looks like a restarted sim: said at most once a second.
  WallThrottle restart_warning_{1.0};
};

}  // namespace cartpole_qlearning
