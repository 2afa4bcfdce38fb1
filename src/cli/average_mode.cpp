#include "headless_modes.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/node_settings/table_folder.h"

#include <cstdio>
#include <iostream>
#include <stdexcept>

namespace cartpole_qlearning
{
// --average TABLE ... --save PATH: the mean of tables trained apart (q_table.h's meanTable), e.g.
// two seeds of config/robust_five_minutes.yaml. Every table is read and checked before anything
// is written: exit 2 on a table that cannot be read or does not fit the first (the message names
// it), 1 when --save's file cannot be written; --save's file is then as it was.
int averageMode(const HeadlessOptions& options)
{
  const std::string table_dir = defaultTableDirectory(options.name_space);
  std::vector<QTable> tables;
  for (const std::string& path : options.average_paths)
  {
    try
    {
      tables.push_back(loadTable(table_dir, path));
    }
    catch (const FileError& e)
    {
      std::cerr << "train_headless: --average " << path << ": " << e.what() << "\n";
      return 2;
    }
  }
  QTable mean;
  try
  {
    mean = meanTable(tables);
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "train_headless: --average: " << e.what() << "\n";
    return 2;
  }
  try
  {
    saveTable(mean, table_dir, options.save_path);
  }
  catch (const FileError& e)
  {
    std::cerr << "train_headless: --save: " << e.what() << "\n";
    return 1;
  }
  if (!options.quiet)
    std::printf("saved the mean of %zu tables (%llu episodes, %llu steps between them) to %s\n", tables.size(),
                static_cast<unsigned long long>(mean.episodes), static_cast<unsigned long long>(mean.steps),
                tablePath(table_dir, options.save_path).c_str());
  return 0;
}

}  // namespace cartpole_qlearning
