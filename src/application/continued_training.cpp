#include "cartpole_qlearning/application/continued_training.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"

namespace cartpole_qlearning
{
std::uint64_t ContinuedTraining::seed(const std::optional<std::uint64_t>& given) const
{
  return given ? *given : record ? record->seed : 0;
}

bool ContinuedTraining::nothingToTrain(std::uint64_t max_episodes) const
{
  return table_episodes >= max_episodes;
}

bool ContinuedTraining::finished() const
{
  return record && !record->finished.empty();
}

bool ContinuedTraining::solved() const
{
  return record && record->finished == "solved";
}

ContinuedTraining resumedTraining(const std::string& table_dir, const std::string& given_folder)
{
  const std::string folder = withoutTrailingSlashes(given_folder);
  // The largest record a run writes is a few kilobytes (its solved window).
  constexpr std::size_t kMaxRecordBytes = 1 << 20;
  ContinuedTraining resumed;
  try
  {
    resumed.record = parseRunRecord(readFileUnder(table_dir, folder + "/" + kRunRecordFile, kMaxRecordBytes));
  }
  catch (const FileError&)
  {
  }
  if (resumed.finished())
    return resumed;
  try
  {
    resumed.table_episodes = loadQTableUnder(table_dir, folder + "/" + kRunTableFile).episodes;
  }
  catch (const FileError&)
  {
  }
  return resumed;
}

ContinuedTraining loadedTraining(const std::function<QTable()>& read_table)
{
  ContinuedTraining loaded;
  try
  {
    loaded.table_episodes = read_table().episodes;
  }
  catch (const FileError&)
  {
  }
  return loaded;
}

}  // namespace cartpole_qlearning
