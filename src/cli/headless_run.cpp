#include "headless_run.h"

#include "cartpole_qlearning/application/robustness_suite.h"
#include "cartpole_qlearning/learning/trace.h"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>

namespace cartpole_qlearning
{
namespace
{
std::atomic<int> g_signal{0};
std::atomic<bool> g_stop{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "set from a signal handler");

void onSignal(int signal)
{
  g_signal.store(signal);
  g_stop.store(true);
}
}  // namespace

HeadlessRun::HeadlessRun(const HeadlessOptions& options, const HeadlessSetup& setup, std::uint64_t seed)
  : options_(options),
    setup_(setup),
    settings_(headlessRunSettings(options, seed, setup.table_dir, setup.config_path, packagePath())),
    trainer_(setup.config, seed, options.robots, !options.evaluating()),
    robot_names_(robotNamespaces(options.robots))
{
  if (options.greedy_check > 0 && !options.evaluating())
    greedy_check_ =
        std::make_unique<GreedyCheck>(setup.config, static_cast<unsigned>(options.greedy_check), greedyCheckSeed(seed));
  settings_.config_origin = setup.config_origin;
  settings_.config_warning = setup.config_warning;
}

HeadlessRun::~HeadlessRun() = default;

std::optional<int> HeadlessRun::start()
{
  const TrainingConfig& config = setup_.config;
  try
  {
    application_ = std::make_unique<RunApplication>(settings_, config, trainer_.session());
    if (!options_.evaluating() && options_.trace)
    {
      // Only the trace names states (one name per table row: built for it alone).
      trainer_.session().setTrace(
          [this, &config, names = stateNames(config.agent)](std::size_t robot, const TraceStep& step) {
            const std::string& name = robot_names_[robot];
            std::printf("%s%s\n", options_.robots > 1 ? (name + ": ").c_str() : "",
                        traceLine(step, names, config.agent.actions).c_str());
          });
    }
    error_ =
        printLog(options_.resume_folder.empty() ? application_->start() : application_->resume(options_.resume_folder),
                 options_.quiet);
  }
  catch (const RunSettingError& e)
  {
    std::cerr << "train_headless: --stats-csv " << options_.stats_csv_path << " is not allowed (" << e.why << ")\n";
    return 2;
  }
  catch (const ConfigError& e)
  {
    // Named by the option whose table or folder it is.
    const std::string option = !options_.resume_folder.empty() ? "--resume " + options_.resume_folder + ": "
                               : options_.evaluating()         ? "--evaluate " + options_.evaluate_path + ": "
                               : !options_.load_path.empty()   ? "--load " + options_.load_path + ": "
                                                               : "";
    std::cerr << "train_headless: " << option << e.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

TrainingResult HeadlessRun::run()
{
  struct sigaction action = {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);

  const TrainingConfig& config = setup_.config;
  std::string returns;
  const TrainingResult result = trainer_.runUntil(
      [&](const EpisodeSummary& s) {
        if (options_.print_returns)
        {
          char text[32];
          std::snprintf(text, sizeof text, "%s%.17g", returns.empty() ? "" : " ", s.episode_return);
          returns += text;
        }
        const bool training_finished = !options_.evaluating() && config.limits.reached(s.episode, s.solved);
        const EpisodeEnd end = application_->endEpisode(robot_names_[s.robot], training_finished);
        error_ = printLog(end.log, options_.quiet) || error_;
        // What the saved table is worth is a result, as the result line is: --quiet keeps it.
        if (options_.quiet && !end.robustness.empty())
          std::printf(
              "robustness of the saved table%s: %s\n",
              config.limits.until == TrainUntil::SuitePasses ? "" : " (for information: this run's goal was solved)",
              end.robustness.c_str());
        verdict_seconds_ += end.verdict_seconds;
        if (greedy_check_ && greedy_pass_episode_ == 0 && greedy_check_->passes(trainer_.session().table()))
        {
          greedy_pass_episode_ = s.episode;
          greedy_pass_steps_ = s.total_steps;
        }
        goal_reached_ = goal_reached_ || end.goal_reached;
        return end.finished || training_finished;
      },
      &g_stop);
  stopped_ = g_stop.load();
  if (stopped_)
  {
    std::fflush(stdout);
    std::fprintf(stderr, "train_headless: stopped by %s\n", g_signal.load() == SIGINT ? "SIGINT" : "SIGTERM");
    error_ = printLog(application_->shutdown(), options_.quiet) || error_;
  }
  if (options_.print_returns)
    std::printf("returns=%s\n", returns.c_str());
  return result;
}

double HeadlessRun::verdictSeconds() const
{
  return verdict_seconds_;
}

bool HeadlessRun::goalReached() const
{
  return goal_reached_;
}

bool HeadlessRun::stopped() const
{
  return stopped_;
}

void HeadlessRun::addError()
{
  error_ = true;
}

int HeadlessRun::exitStatus() const
{
  return stopped_ ? 128 + g_signal.load() : error_ ? 1 : 0;
}

RunApplication& HeadlessRun::application()
{
  return *application_;
}

const TrainingSession& HeadlessRun::session() const
{
  return trainer_.session();
}

const RunSettings& HeadlessRun::settings() const
{
  return settings_;
}

}  // namespace cartpole_qlearning
