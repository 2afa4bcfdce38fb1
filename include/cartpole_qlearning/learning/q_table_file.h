// The Q-table file: a versioned, self-describing YAML document with a checksum. Saving is
// atomic; loading checks everything before the caller's table is touched.
#pragma once

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table.h"

#include <string>

namespace cartpole_qlearning
{
// Version 3 also says what it takes to run the table: the step it learnt (tau) and the
// configuration that trained it (written as version 2 when the table knows neither). Version 2
// says which features number the rows (bins or tiles, with their parameters); version 1 (bins
// only) is still read, as bins.
constexpr int kQTableFormatVersion = 3;

// Saves atomically (see file_access.h: the target is either the old file or the complete new
// one, whatever happens). Creates missing parent directories. Throws FileError (io/file_access.h: what is wrong, and
// nothing was changed).
void saveQTableFile(const QTable& table, const std::string& path);
// The same for a path under a directory, as services take it: no links, no "..".
void saveQTableUnder(const QTable& table, const std::string& directory, const std::string& path);

// Reads and checks a file: format name, version, shape, counts, finite values and checksum.
// Throws FileError (io/file_access.h: what is wrong, and nothing was changed) saying what is wrong. Whether it fits a
// given agent is the caller's check (QTable::shapeMismatch), made before the live table is replaced.
// A file over max_bytes (maxQTableFileBytes of the table the caller expects) is refused before it
// is read.
QTable loadQTableFile(const std::string& path, std::uint64_t max_bytes = kMaxFileBytes);
QTable loadQTableUnder(const std::string& directory, const std::string& path, std::uint64_t max_bytes = kMaxFileBytes);

// The document's text and its parse, separately (save and load are these plus file handling).
std::string formatQTable(const QTable& table);
QTable parseQTable(const std::string& text);

}  // namespace cartpole_qlearning
