// Where Q-tables are read and written: the table folder, the default table in it, and the path
// rule the node's parameters, its services and train_headless's command line share. A relative
// path lies under the folder; an absolute one given by the user (the settings, the command line)
// is the user's file when the store is told so (train_headless, the node's parameters), else it
// too must lie in the folder; a path through a service always does. A path that escapes the folder is refused.
#pragma once

#include "cartpole_qlearning/common/log_line.h"
#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace cartpole_qlearning
{
// A service's answer (SaveQTable, LoadQTable): success and message, and what to log.
struct ServiceAnswer
{
  bool success = false;
  std::string message;
  LogLines log;
};

// A table read for ~load_q_table, not yet in use: the table, or the answer that refuses it.
struct TableRead
{
  std::optional<QTable> table;
  std::string resolved;   // the file, as messages name it
  ServiceAnswer refusal;  // without a table
};

// What an absolute path the user gives (not a service's caller) names.
enum class AbsolutePaths
{
  MustLieInTheFolder,
  AreTheUsersFiles  // train_headless's command line, the node's parameters: followed as the shell would
};

// The default table of a run trained with the configuration file `config_path`, named after it
// so that training one configuration never replaces another's table: q_table.yaml for
// cartpole.yaml (the default) or no file, q_table_NAME.yaml for NAME.yaml (robust.yaml:
// q_table_robust.yaml).
std::string defaultTableName(const std::string& config_path);

class TableStore
{
public:
  // folder: where tables go. default_table: the table "" names (relative to the folder, or
  // absolute as `absolute` allows; "": none).
  TableStore(std::string folder, std::string default_table, AbsolutePaths absolute);

  // A path the user gives, made absolute ("" the default table). Throws FileError when it
  // escapes the folder (and is not the user's).
  std::string resolve(const std::string& path) const;
  // Reads and writes a table at such a path. Throw FileError.
  QTable load(const std::string& path, std::uint64_t max_bytes = kMaxFileBytes) const;
  void save(const QTable& table, const std::string& path) const;

  // A path through a service, made absolute: "" the default table, anything else under the
  // folder, absolute or not. Throws FileError when it escapes the folder.
  std::string resolveForService(const std::string& path) const;
  // ~save_q_table: writes the table there, saying what or why nothing. Never throws.
  ServiceAnswer serveSave(const QTable& table, const std::string& path) const;
  // ~load_q_table: reads the table there and hands it to `replace`, which puts it in use when it
  // fits and otherwise says what differs (and changes nothing). Never throws. The same as
  // useForService(readForService(path), replace): a controller makes the two steps apart, reading
  // the file (seconds for a large table) while it goes on serving states.
  ServiceAnswer serveLoad(const std::string& path, const std::function<std::string(QTable)>& replace) const;
  // Reads and checks the table there; a file over max_bytes is refused before it is read. Touches
  // nothing but the file: safe beside any use of the table in use. Never throws.
  TableRead readForService(const std::string& path, std::uint64_t max_bytes = kMaxFileBytes) const;
  // Hands a table read to `replace`, or answers with its refusal. Never throws.
  ServiceAnswer useForService(TableRead read, const std::function<std::string(QTable)>& replace) const;

  const std::string& folder() const
  {
    return folder_;
  }

private:
  bool isUsersFile(const std::string& path) const;

  std::string folder_;
  std::string default_table_;
  AbsolutePaths absolute_;
};

}  // namespace cartpole_qlearning
