#include "cartpole_qlearning/application/final_table_check.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"

namespace cartpole_qlearning
{
bool replacesDefaultTable(bool solved, bool stopped, bool has_default_table)
{
  return solved && !stopped && has_default_table;
}

bool fileHoldsTable(const std::string& path, const QTable& table)
{
  try
  {
    const QTable saved = loadQTableFile(path);
    return saved.episodes == table.episodes && saved.steps == table.steps;
  }
  catch (const FileError&)
  {
    return false;
  }
}

}  // namespace cartpole_qlearning
