#include "headless_modes.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/node_settings/table_folder.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <system_error>

namespace cartpole_qlearning
{
// --average TABLE ... --save PATH: the mean of tables trained apart (q_table.h's TableMean), e.g.
// two seeds of config/robust_five_minutes.yaml. The tables are read one at a time (a table may
// hold 160 MB) and each is checked before anything is written: exit 2 on a bad --save, on the
// same file given twice, on a table that cannot be read or does not fit the first (the message
// names it and what differs), 1 when --save's file cannot be written; --save's file is then as it
// was. --save may name one of the tables: every table is read before the mean is written.
int averageMode(const HeadlessOptions& options)
{
  const std::string table_dir = defaultTableDirectory(options.name_space);
  if (!saveStaysInTableFolder(table_dir, options.save_path))
    return 2;
  // One run's table given twice would count that run twice.
  std::vector<std::pair<std::string, std::string>> files;  // as given, and the file itself
  for (const std::string& path : options.average_paths)
  {
    std::string file;
    try
    {
      std::error_code ignored;  // a file that is not there is said when it is read
      file = std::filesystem::weakly_canonical(tablePath(table_dir, path), ignored).string();
    }
    catch (const FileError& e)
    {
      std::cerr << "train_headless: --average " << path << ": " << e.what() << "\n";
      return 2;
    }
    for (const auto& [given, earlier] : files)
      if (!file.empty() && file == earlier)
      {
        std::cerr << "train_headless: --average " << path << " is the file --average " << given << " gave already ("
                  << file << "): each run's table once\n";
        return 2;
      }
    files.emplace_back(path, file);
  }
  std::optional<TableMean> sum;
  for (const std::string& path : options.average_paths)
  {
    try
    {
      QTable table = loadTable(table_dir, path);
      if (!sum)
        sum.emplace(std::move(table));
      else
        sum->add(table);
    }
    catch (const FileError& e)
    {
      std::cerr << "train_headless: --average " << path << ": " << e.what() << "\n";
      return 2;
    }
    catch (const std::invalid_argument& e)
    {
      std::cerr << "train_headless: --average " << path << ": " << e.what()
                << " (the first: " << options.average_paths.front() << ")\n";
      return 2;
    }
  }
  QTable mean;
  try
  {
    mean = sum->mean();
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
    std::printf("saved the mean of %zu tables (%llu episodes, %llu steps between them) to %s\n", sum->count(),
                static_cast<unsigned long long>(mean.episodes), static_cast<unsigned long long>(mean.steps),
                tablePath(table_dir, options.save_path).c_str());
  return 0;
}

}  // namespace cartpole_qlearning
