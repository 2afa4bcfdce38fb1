// What a run measures and reports as it goes: steps per second (the learner's, and each robot's),
// the progress line every training/progress_every episodes, the time since the start, and an
// evaluation's episodes and verdict. The clock is injected, so that tests drive it.
#pragma once

#include "cartpole_qlearning/application/run_settings.h"
#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

namespace cartpole_qlearning
{
// The greedy evaluation's outcome so far.
struct EvaluationVerdict
{
  std::uint64_t episodes = 0;
  std::uint64_t balanced = 0;  // reached the step limit without falling
  double mean_return = 0.0;
};

class RunMeters
{
public:
  using SteadyClock = std::function<std::chrono::steady_clock::time_point()>;

  // config: progress_every, the task's solved window and step limit. settings: an evaluation's
  // episodes, case and pass count.
  RunMeters(const TrainingConfig& config, const RunSettings& settings, SteadyClock steady);

  // The run starts now, with the table in use `total_steps` steps into its training.
  void start(std::uint64_t total_steps);
  // Another table is in use from now (a load): rates count its steps from here.
  void countStepsFrom(std::uint64_t total_steps);

  struct Rates
  {
    double steps_per_second = 0.0;        // the learner's, since the previous episode's end (any robot)
    double robot_steps_per_second = 0.0;  // this robot's, since its own previous end
  };
  // An episode of `robot` has ended now: reads the clock, which the rest of this episode's end
  // (progress, secondsRunning) goes by.
  Rates episodeEnded(const std::string& robot, const EpisodeSummary& summary);
  // The progress line, when one is due at this episode (not prefixed: train_headless prints it as
  // it is); else nothing.
  void addProgress(const EpisodeSummary& summary, LogLines& log);
  // From the start to the last episode's end.
  double secondsRunning() const;

  // Evaluation: says the episode, and after the evaluation's episodes its verdict. True when the
  // verdict is given (the evaluation is over).
  bool addEvaluationEpisode(const EpisodeSummary& summary, LogLines& log);
  EvaluationVerdict verdict(const TrainingSession& session) const;

private:
  using TimePoint = std::chrono::steady_clock::time_point;

  TrainingConfig config_;
  std::uint64_t evaluation_episodes_;
  std::string evaluation_case_;
  std::uint64_t evaluation_pass_;
  SteadyClock steady_;

  TimePoint started_;
  TimePoint now_;  // the last episode's end
  TimePoint last_episode_end_;
  TimePoint last_progress_;
  std::map<std::string, TimePoint> robot_last_end_;
  std::uint64_t steps_at_last_episode_ = 0;
  std::uint64_t steps_at_last_progress_ = 0;
  std::uint64_t balanced_ = 0;  // evaluation episodes that reached the step limit
};

}  // namespace cartpole_qlearning
