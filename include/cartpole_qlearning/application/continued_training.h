// Training that goes on from earlier training, as train_headless starts it: from a table (--load
// TABLE) or from the last checkpoint of a run folder (--resume FOLDER). Read before the run
// starts, it decides the seed (a resumed run's own unless another is given), whether anything is
// left to train, and what a resumed run that had finished reports. A table or folder that cannot
// be read decides nothing here: RunApplication says what is wrong with it when the run starts.
#pragma once

#include "cartpole_qlearning/application/run_folder.h"
#include "cartpole_qlearning/learning/q_table.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
struct ContinuedTraining
{
  std::optional<RunRecord> record;  // --resume: the run's record, when it can be read
  // The episodes of training the table it goes on from holds: --load's table, or the checkpoint
  // table of --resume's folder (not its record's count: a kill between the two saves leaves the
  // record a checkpoint behind, and the table wins, as in RunApplication::resume). 0 when the
  // table cannot be read, and for a resumed run that has finished (it reports its counts instead).
  std::uint64_t table_episodes = 0;

  // The seed the run uses: the one given, else a resumed run's own, else 0.
  std::uint64_t seed(const std::optional<std::uint64_t>& given) const;
  // Training ends at episode max_episodes, which counts the table's own: a table at or past it
  // has nothing to train (else one more episode would run).
  bool nothingToTrain(std::uint64_t max_episodes) const;
  // A resumed run whose record says it finished, and whether it was solved (its result line).
  bool finished() const;
  bool solved() const;
};

// --resume FOLDER: the record and checkpoint table of the run folder FOLDER under table_dir.
ContinuedTraining resumedTraining(const std::string& table_dir, const std::string& folder);
// --load TABLE: read_table reads it (by the services' path rule); a FileError leaves its count 0.
ContinuedTraining loadedTraining(const std::function<QTable()>& read_table);

}  // namespace cartpole_qlearning
