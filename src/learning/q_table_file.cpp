#include "cartpole_qlearning/learning/q_table_file.h"

#include "q_table_document.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>

namespace cartpole_qlearning
{
using namespace q_table_document;

void saveQTableFile(const QTable& table, const std::string& path)
{
  writeFileAtomically(path, formatQTable(table));
}

void saveQTableUnder(const QTable& table, const std::string& directory, const std::string& path)
{
  writeFileUnder(directory, path, formatQTable(table));
}

namespace
{
// The most bytes a table file may have, by its header (the text before its values): the rows
// and actions it claims. What the header says is checked in full when the file is parsed.
std::uint64_t claimedFileBytes(const std::string& head)
{
  const std::size_t values_at = head.find("\nvalues:\n");
  if (values_at == std::string::npos)
    refuse("no 'values:' line in its first " + std::to_string(head.size()) +
           " bytes: not a Q-table file of a format this build reads");
  const YAML::Node root = loadTableYaml(head.substr(0, values_at + 1));
  if (!root.IsMap())
    refuse("not a Q-table file (expected a YAML mapping with 'format: " + std::string(kFormatName) + "')");
  const char* const rows_key = root["rows"] ? "rows" : "states";
  const std::uint64_t rows = readCount(required(root, rows_key), rows_key);
  const std::uint64_t actions = readNumbers(required(root, "actions"), "actions", 0).size();
  if (actions == 0 || rows > kMaxTableValues || rows * actions > kMaxTableValues)
    refuse(std::to_string(rows) + " rows of " + std::to_string(actions) + " values are more than the " +
           std::to_string(kMaxTableValues) + " a table may hold");
  return maxQTableFileBytes(rows, actions);
}

QTable parseQTableFrom(const std::string& text, const std::string& shown)
{
  try
  {
    return parseQTable(text);
  }
  catch (const FileError& e)
  {
    refuse(shown + ": " + e.what());
  }
}
}  // namespace

QTable loadQTableFile(const std::string& path, std::uint64_t max_bytes)
{
  return parseQTableFrom(readFile(path, std::min(max_bytes, kMaxFileBytes), claimedFileBytes), path);
}

QTable loadQTableUnder(const std::string& directory, const std::string& path, std::uint64_t max_bytes)
{
  return parseQTableFrom(readFileUnder(directory, path, std::min(max_bytes, kMaxFileBytes), claimedFileBytes),
                         resolvePathUnder(directory, path));
}
}  // namespace cartpole_qlearning
