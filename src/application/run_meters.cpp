#include "cartpole_qlearning/application/run_meters.h"

#include "cartpole_qlearning/application/robustness_suite.h"

#include <utility>

namespace cartpole_qlearning
{
namespace
{
unsigned long long count(std::uint64_t value)
{
  return static_cast<unsigned long long>(value);
}

double seconds(std::chrono::steady_clock::duration duration)
{
  return std::chrono::duration<double>(duration).count();
}
}  // namespace

RunMeters::RunMeters(const TrainingConfig& config, const RunSettings& settings, SteadyClock steady)
  : config_(config),
    evaluation_episodes_(settings.evaluation_episodes),
    evaluation_case_(settings.evaluation_case),
    evaluation_pass_(settings.evaluation_pass),
    steady_(std::move(steady))
{
}

void RunMeters::start(std::uint64_t total_steps)
{
  started_ = now_ = last_episode_end_ = last_progress_ = steady_();
  countStepsFrom(total_steps);
}

void RunMeters::countStepsFrom(std::uint64_t total_steps)
{
  steps_at_last_episode_ = steps_at_last_progress_ = total_steps;
}

RunMeters::Rates RunMeters::episodeEnded(const std::string& robot, const EpisodeSummary& s)
{
  now_ = steady_();
  const auto robot_end = robot_last_end_.emplace(robot, started_).first;
  const double wall = seconds(now_ - last_episode_end_);
  const double robot_wall = seconds(now_ - robot_end->second);
  last_episode_end_ = robot_end->second = now_;
  Rates rates;
  rates.steps_per_second = wall > 0.0 ? static_cast<double>(s.total_steps - steps_at_last_episode_) / wall : 0.0;
  rates.robot_steps_per_second = robot_wall > 0.0 ? s.steps / robot_wall : 0.0;
  steps_at_last_episode_ = s.total_steps;
  return rates;
}

void RunMeters::addProgress(const EpisodeSummary& s, LogLines& log)
{
  const std::uint64_t every = config_.limits.progress_every;
  if (every == 0 || s.episode % every != 0)
    return;
  const double interval = seconds(now_ - last_progress_);
  const double rate = interval > 0.0 ? static_cast<double>(s.total_steps - steps_at_last_progress_) / interval : 0.0;
  log.push_back({LogLine::Level::Info, progressLine(s, config_.task.solved_window, rate, secondsRunning()), false});
  steps_at_last_progress_ = s.total_steps;
  last_progress_ = now_;
}

double RunMeters::secondsRunning() const
{
  return seconds(now_ - started_);
}

bool RunMeters::addEvaluationEpisode(const EpisodeSummary& s, LogLines& log)
{
  balanced_ += s.truncated && !s.terminated;
  // A return other than CartPole-v1's (+1 a step) is said with its meaning: on the first episode
  // and on the verdict.
  const RewardScheme reward = config_.task.scoreReward();
  const std::string meaning =
      reward == RewardScheme::Gymnasium ? "" : " (" + toString(reward) + "'s reward: " + rewardMeaning(reward) + ")";
  log.push_back(
      {LogLine::Level::Info,
       formatText("evaluation episode %llu: %u steps, return %.1f%s, %s", count(s.episode), s.steps, s.episode_return,
                  s.episode == 1 ? meaning.c_str() : "", s.terminated ? "fell" : "balanced to the step limit")});
  if (evaluation_episodes_ == 0 || s.episode < evaluation_episodes_)
    return false;
  std::string verdict = formatText(
      "EVALUATED %llu episodes: %llu balanced to the step limit (%u steps), mean return %.1f%s", count(s.episode),
      count(balanced_), config_.task.max_episode_steps, shownReturn(s.mean_return_window, 1), meaning.c_str());
  if (!evaluation_case_.empty())
    verdict += formatText("; %s: %s (needs %llu)", evaluation_case_.c_str(),
                          balanced_ >= evaluation_pass_ ? "PASSED" : "FAILED", count(evaluation_pass_));
  log.push_back({LogLine::Level::Info, verdict});
  return true;
}

EvaluationVerdict RunMeters::verdict(const TrainingSession& session) const
{
  EvaluationVerdict verdict;
  verdict.episodes = session.episodesEnded();
  verdict.balanced = balanced_;
  verdict.mean_return = verdict.episodes > 0 ? session.lastEpisode().mean_return_window : 0.0;
  return verdict;
}

}  // namespace cartpole_qlearning
