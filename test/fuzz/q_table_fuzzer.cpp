// libFuzzer target: the Q-table file parser. Whatever the bytes, parseQTable returns a table or
// throws FileError; any other exception, a crash or a sanitizer report is a bug. A table
// it accepts must write back to text that parses to the same table (a version 1 table is
// written back as version 2; bins and tiles alike: shapeMismatch compares the features). The
// corpus holds both versions and both kinds of features.
#include "cartpole_qlearning/learning/q_table_file.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace cartpole_qlearning;
  const std::string text(reinterpret_cast<const char*>(data), size);
  QTable table;
  try
  {
    table = parseQTable(text);
  }
  catch (const FileError&)
  {
    return 0;
  }
  const QTable again = parseQTable(formatQTable(table));
  if (!again.shapeMismatch(table).empty() || again.episodes != table.episodes || again.steps != table.steps ||
      again.values().size() != table.values().size() ||
      std::memcmp(again.values().data(), table.values().data(), table.values().size() * sizeof(double)) != 0)
    std::abort();  // an accepted table that does not round-trip
  return 0;
}
