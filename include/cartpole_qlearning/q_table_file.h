// The Q-table file: a versioned, self-describing YAML document with a checksum. Saving is
// atomic; loading checks everything before the caller's table is touched.
#pragma once

#include "cartpole_qlearning/q_table.h"

#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
// Anything wrong with a path or a file; the message says what, and nothing was changed.
class QTableFileError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

constexpr int kQTableFormatVersion = 1;

// Writes to a temporary file beside the target, flushes it to disk and renames it over the
// target, so the target is either the old file or the complete new one. Creates missing
// parent directories. Throws QTableFileError.
void saveQTableFile(const QTable& table, const std::string& path);

// Reads and checks a file: format name, version, shape, counts, finite values and checksum.
// Throws QTableFileError saying what is wrong. Whether it fits a given agent is the caller's
// check (QTable::shapeMismatch), made before the live table is replaced.
QTable loadQTableFile(const std::string& path);

// The document's text and its parse, separately (save and load are these plus file handling).
std::string formatQTable(const QTable& table);
QTable parseQTable(const std::string& text);

// Resolves a user-given path under a directory: a relative path is taken from the directory,
// ".." and symbolic links are resolved, and the result must lie inside the directory (an
// absolute path too). Throws QTableFileError for an empty path or one that escapes.
std::string resolvePathUnder(const std::string& directory, const std::string& path);

}  // namespace cartpole_qlearning
