#include "headless_run.h"

#include "cartpole_qlearning/application/continued_training.h"
#include "cartpole_qlearning/application/final_table_check.h"

#include <cstdio>
#include <iostream>

namespace cartpole_qlearning
{
// Training: from scratch, from a table (--load) or on from a run folder's checkpoint (--resume),
// ending with "solved=true|false episodes=N steps=M wall_s=T" (the session's counts: a loaded or
// resumed table's episodes included, as the node counts them; after a stop, M is the saved table's
// steps, the unfinished episode's included). Exit 2 when it cannot start (a bad
// table or folder, nothing left to train), 1 when a table could not be saved.
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
    std::printf("solved=%s episodes=%llu steps=%llu wall_s=0.000000\n", from.solved() ? "true" : "false",
                static_cast<unsigned long long>(last.episode), static_cast<unsigned long long>(last.total_steps));
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
  // Microseconds: a run to solved takes a few milliseconds.
  std::printf("solved=%s episodes=%llu steps=%llu wall_s=%.6f\n", result.solved ? "true" : "false",
              static_cast<unsigned long long>(last.episode), static_cast<unsigned long long>(steps), result.wall_s);
  return run.exitStatus();
}

}  // namespace cartpole_qlearning
