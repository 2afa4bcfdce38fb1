// A run of the controller's application with the core's trainer: training or a greedy
// evaluation. It makes the node's RunApplication calls in the node's order and prints what they
// say; the modes print their result lines.
#pragma once

#include "headless_modes.h"

#include "cartpole_qlearning/application/greedy_check.h"
#include "cartpole_qlearning/application/headless_trainer.h"
#include "cartpole_qlearning/application/run_application.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
class HeadlessRun
{
public:
  HeadlessRun(const HeadlessOptions& options, const HeadlessSetup& setup, std::uint64_t seed);
  ~HeadlessRun();

  // Starts the application (--resume: on from the run folder's checkpoint): nullopt, or the exit
  // status when it cannot start, after saying why.
  std::optional<int> start();
  // Episodes until the application or the limits end the run, or until SIGINT or SIGTERM stops it
  // (then the save on shutdown, as the controller's); then --returns' line.
  TrainingResult run();

  // Of run()'s seconds, those the saved table's final verdict (the suite) took.
  double verdictSeconds() const;
  // Training ended where it trained to: solved, under until suite_passes the suite passed, going on
  // after solved max_episodes.
  bool goalReached() const;
  bool stopped() const;
  // A failure the mode found after the run (it has said it).
  void addError();
  // 128 + the signal's number when stopped, else 1 when an error was said, else 0.
  int exitStatus() const;

  // --greedy-check: the first episode after which it passed, and the training steps then (0: never).
  std::uint64_t greedyPassEpisode() const
  {
    return greedy_pass_episode_;
  }
  std::uint64_t greedyPassSteps() const
  {
    return greedy_pass_steps_;
  }

  RunApplication& application();
  const TrainingSession& session() const;
  const RunSettings& settings() const;

private:
  const HeadlessOptions& options_;
  const HeadlessSetup& setup_;
  RunSettings settings_;
  HeadlessTrainer trainer_;
  std::vector<std::string> robot_names_;
  std::unique_ptr<RunApplication> application_;
  std::unique_ptr<GreedyCheck> greedy_check_;
  std::uint64_t greedy_pass_episode_ = 0;
  std::uint64_t greedy_pass_steps_ = 0;
  double verdict_seconds_ = 0.0;
  bool goal_reached_ = false;
  bool stopped_ = false;
  bool error_ = false;
};

}  // namespace cartpole_qlearning
