#include "cartpole_qlearning/application/table_store.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include <cstdint>
#include <utility>

namespace cartpole_qlearning
{
namespace
{
ServiceAnswer refusedLoad(const std::string& why)
{
  ServiceAnswer answer;
  answer.message = "refused, the table in use is unchanged: " + why;
  answer.log.push_back({LogLine::Level::Warn, "load_q_table: " + answer.message});
  return answer;
}
}  // namespace

std::string defaultTableName(const std::string& config_path)
{
  std::string name = config_path.substr(config_path.find_last_of('/') + 1);
  for (const char* extension : {".yaml", ".yml"})
  {
    const std::string ext(extension);
    if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0)
    {
      name.resize(name.size() - ext.size());
      break;
    }
  }
  return name.empty() || name == "cartpole" ? "q_table.yaml" : "q_table_" + name + ".yaml";
}

TableStore::TableStore(std::string folder, std::string default_table, AbsolutePaths absolute)
  : folder_(std::move(folder)), default_table_(std::move(default_table)), absolute_(absolute)
{
}

bool TableStore::isUsersFile(const std::string& path) const
{
  return absolute_ == AbsolutePaths::AreTheUsersFiles && !path.empty() && path.front() == '/';
}

std::string TableStore::resolve(const std::string& path) const
{
  const std::string& named = path.empty() ? default_table_ : path;
  return isUsersFile(named) ? named : resolvePathUnder(folder_, named);
}

QTable TableStore::load(const std::string& path, std::uint64_t max_bytes) const
{
  const std::string& named = path.empty() ? default_table_ : path;
  return isUsersFile(named) ? loadQTableFile(named, max_bytes) : loadQTableUnder(folder_, named, max_bytes);
}

void TableStore::save(const QTable& table, const std::string& path) const
{
  const std::string& named = path.empty() ? default_table_ : path;
  if (isUsersFile(named))
    saveQTableFile(table, named);
  else
    saveQTableUnder(table, folder_, named);
}

std::string TableStore::resolveForService(const std::string& path) const
{
  // Under the folder whatever the store allows the user: a service's caller is not the user at
  // the shell. "" is the default table, which the user named.
  return path.empty() ? resolve("") : resolvePathUnder(folder_, path);
}

ServiceAnswer TableStore::serveSave(const QTable& table, const std::string& path) const
{
  ServiceAnswer answer;
  try
  {
    const std::string resolved = resolveForService(path);
    if (path.empty())
      save(table, "");
    else
      saveQTableUnder(table, folder_, path);
    answer.success = true;
    answer.message = "saved " + std::to_string(table.episodes) + " episodes, " + std::to_string(table.steps) +
                     " steps of training to " + resolved;
  }
  catch (const std::exception& e)  // FileError, or anything else: never out of a service
  {
    answer.message = std::string("nothing written: ") + e.what();
  }
  answer.log.push_back(
      {answer.success ? LogLine::Level::Info : LogLine::Level::Warn, "save_q_table: " + answer.message});
  return answer;
}

ServiceAnswer TableStore::serveLoad(const std::string& path, const std::function<std::string(QTable)>& replace) const
{
  return useForService(readForService(path), replace);
}

TableRead TableStore::readForService(const std::string& path, std::uint64_t max_bytes) const
{
  TableRead read;
  try
  {
    read.resolved = resolveForService(path);
    read.table = path.empty() ? load("", max_bytes) : loadQTableUnder(folder_, path, max_bytes);
  }
  catch (const std::exception& e)  // FileError, or anything else (std::bad_alloc): never out of a service
  {
    read.refusal = refusedLoad(e.what());
  }
  return read;
}

ServiceAnswer TableStore::useForService(TableRead read, const std::function<std::string(QTable)>& replace) const
{
  if (!read.table)
    return read.refusal;
  try
  {
    const std::uint64_t episodes = read.table->episodes;
    const std::uint64_t steps = read.table->steps;
    const std::string mismatch = replace(std::move(*read.table));
    if (!mismatch.empty())
      throw FileError(read.resolved + " does not fit this controller: " + mismatch);
    ServiceAnswer answer;
    answer.success = true;
    answer.message = "loaded " + read.resolved + " (" + std::to_string(episodes) + " episodes, " +
                     std::to_string(steps) + " steps of training)";
    answer.log.push_back({LogLine::Level::Info, "load_q_table: " + answer.message});
    return answer;
  }
  catch (const std::exception& e)
  {
    return refusedLoad(e.what());
  }
}

}  // namespace cartpole_qlearning
