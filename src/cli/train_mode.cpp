#include "headless_run.h"

#include "cartpole_qlearning/application/continued_training.h"
#include "cartpole_qlearning/application/final_table_check.h"

#include <cstdio>
#include <iostream>

namespace cartpole_qlearning
{
namespace
{
// What training runs until: "solved", "max_episodes" (it goes on after solved) or "suite_passes".
const char* trainedUntil(const TrainingLimits& limits)
{
  return limits.until == TrainUntil::SuitePasses ? "suite_passes"
         : limits.goesOnAfterSolved()            ? "max_episodes"
                                                 : "solved";
}

// The result line: what the run trained until and whether it got there, whether the window ever
// reached solved (n/a where the task's returns cannot: sutton_barto's reward, episodes shorter than
// solved_mean_return), the counts, and the seconds of training and of the saved table's verdict
// apart (microseconds: a run to solved takes a few milliseconds).
void printResult(const TrainingConfig& config, bool reached, bool solved, std::uint64_t episodes, std::uint64_t steps,
                 double train_s, double verdict_s)
{
  std::printf("until=%s reached=%s solved=%s episodes=%llu steps=%llu train_s=%.6f verdict_s=%.6f\n",
              trainedUntil(config.limits), reached ? "true" : "false",
              !config.task.solvable() ? "n/a"
              : solved                ? "true"
                                      : "false",
              static_cast<unsigned long long>(episodes), static_cast<unsigned long long>(steps), train_s, verdict_s);
}
}  // namespace

// Training: from scratch, from a table (--load) or on from a run folder's checkpoint (--resume),
// ending with "until=U reached=true|false solved=true|false|n/a episodes=N steps=M train_s=T
// verdict_s=V" (the session's counts: a loaded or resumed table's episodes included, as the node
// counts them; after a stop, M is the saved table's steps, the unfinished episode's included). Exit 2 when it cannot
// start (a bad table or folder, nothing left to train), 1 when a table could not be saved.
int trainMode(const HeadlessOptions& options, const HeadlessSetup& setup)
{
  const bool resuming = !options.resume_folder.empty();
  ContinuedTraining from;
  if (resuming)
    from = resumedTraining(setup.table_dir, options.resume_folder);
  else if (!options.load_path.empty())
    from = loadedTraining([&] { return loadTable(setup.table_dir, options.load_path); });
  const std::uint64_t max_episodes = setup.config.limits.max_episodes;
  if ((resuming || !options.load_path.empty()) && from.nothingToTrain(max_episodes))
  {
    std::cerr << "train_headless: " << (resuming ? "--resume " + options.resume_folder : "--load " + options.load_path)
              << ": its table has " << from.table_episodes
              << " episodes of training already, and training ends at episode " << max_episodes
              << " (--max-episodes, else training/max_episodes): nothing to train\n";
    return 2;
  }

  HeadlessRun run(options, setup, from.seed(options.seed));
  if (const std::optional<int> status = run.start())
    return *status;
  if (run.application().finished())
  {
    // A resumed run that had finished: nothing to train; its counts, as a result line.
    const EpisodeSummary& last = run.session().lastEpisode();
    // Its record says how it finished ("solved", "suite_passed" or "max_episodes"): where it was
    // going, unless it ran out of episodes first.
    const bool reached =
        setup.config.limits.goesOnAfterSolved() || (from.record && from.record->finished != "max_episodes");
    printResult(setup.config, reached, from.solved(), last.episode, last.total_steps, 0.0, 0.0);
    return 0;
  }
  const TrainingResult result = run.run();

  // A solved run's default table that could not be written is said in the final line above;
  // it is an error all the same.
  const EpisodeSummary& last = run.session().lastEpisode();
  if (replacesDefaultTable(last.solved, run.stopped(), !run.settings().q_table_path.empty()) &&
      !fileHoldsTable(run.application().resolve(""), run.session().table()))
  {
    std::fflush(stdout);
    std::fprintf(stderr, "train_headless: the table was not saved to %s\n", run.application().resolve("").c_str());
    run.addError();
  }
  // Stopped (Ctrl-C), the table saved on the way out has learnt from the unfinished episode's steps
  // too, and the line before this one says so: steps= counts what that table counts, so that the
  // two agree (episodes= counts finished episodes, as the table does).
  const std::uint64_t steps = run.stopped() ? run.session().table().steps : last.total_steps;
  if (options.greedy_check > 0)
  {
    if (run.greedyPassEpisode() > 0)
      std::printf("greedy_check=%llu first_pass_steps=%llu first_pass_episode=%llu\n",
                  static_cast<unsigned long long>(options.greedy_check),
                  static_cast<unsigned long long>(run.greedyPassSteps()),
                  static_cast<unsigned long long>(run.greedyPassEpisode()));
    else
      std::printf("greedy_check=%llu first_pass_steps=never first_pass_episode=never\n",
                  static_cast<unsigned long long>(options.greedy_check));
  }
  printResult(setup.config, run.goalReached(), result.solved, last.episode, steps, result.wall_s - run.verdictSeconds(),
              run.verdictSeconds());
  return run.exitStatus();
}

}  // namespace cartpole_qlearning
