#include "cartpole_qlearning/learning/q_table_file.h"
#include "cartpole_qlearning/io/number_text.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <charconv>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <locale>
#include <optional>
#include <sstream>
#include <string_view>

namespace cartpole_qlearning
{
namespace
{
constexpr const char* kFormatName = "cartpole_qlearning/q_table";

// FNV-1a over 64-bit words: the bit patterns of every number that defines the table, so a
// flipped digit anywhere in them is caught even when the text still parses.
class Checksum
{
public:
  void add(std::uint64_t word)
  {
    for (int i = 0; i < 8; ++i)
    {
      hash_ ^= (word >> (8 * i)) & 0xFF;
      hash_ *= 0x100000001B3ULL;
    }
  }
  void add(double value)
  {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    add(bits);
  }
  std::string text() const
  {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "fnv1a64:%016llx", static_cast<unsigned long long>(hash_));
    return buffer;
  }

private:
  std::uint64_t hash_ = 0xCBF29CE484222325ULL;
};

std::string checksumOf(const QTable& table)
{
  Checksum sum;
  const FeatureParams& f = table.features();
  const DiscretiserParams& d = f.discretiser;
  // A bins table sums as version 1 did, so that version 1 files keep their checksums; a tiles
  // table sums its tilings first and its tiles in place of the bins.
  const bool tiles = f.kind == FeatureKind::Tiles;
  if (tiles)
    sum.add(static_cast<std::uint64_t>(f.tilings));
  for (std::size_t i = 0; i < kStateDimensions; ++i)
  {
    sum.add(static_cast<std::uint64_t>(tiles ? f.tiles[i] : d.bins[i]));
    sum.add(d.lower[i]);
    sum.add(d.upper[i]);
  }
  for (double a : table.actions())
    sum.add(a);
  // Summed only when on, so that every other table keeps its checksum.
  if (f.previous_action)
    sum.add(std::uint64_t{1});
  // Version 3's keys, summed only when present: a table without them keeps its checksum.
  if (table.tau > 0.0)
  {
    sum.add(std::uint64_t{3});
    sum.add(table.tau);
  }
  if (!table.trained_with.empty())
  {
    sum.add(std::uint64_t{table.trained_with.size()});
    for (const char c : table.trained_with)
      sum.add(static_cast<std::uint64_t>(static_cast<unsigned char>(c)));
  }
  sum.add(table.episodes);
  sum.add(table.steps);
  for (double v : table.values())
    sum.add(v);
  return sum.text();
}

// The shortest decimal (15 to 17 significant digits, as printf's %g writes them) that reads back
// as the same double: exact, and 2.4 stays "2.4" rather than "2.3999999999999999". With to_chars
// and from_chars (locale-free; io/number_text.h where the library lacks them), not string
// streams: a table of 2,000,000 values took 6 s to write through streams.
void appendExact(std::string& text, double value)
{
  char buffer[64];
  for (int precision = 15;; ++precision)
  {
    const std::to_chars_result written = writeGeneral(buffer, buffer + sizeof buffer, value, precision);
    double back = 0.0;
    const std::from_chars_result read = readDouble(buffer, written.ptr, back);
    if (precision == 17 || (read.ec == std::errc() && std::memcmp(&back, &value, sizeof value) == 0))
    {
      text.append(buffer, written.ptr);
      return;
    }
  }
}

std::string exact(double value)
{
  std::string text;
  appendExact(text, value);
  return text;
}

template <typename Container>
std::string flowList(const Container& values)
{
  std::string text = "[";
  bool first = true;
  for (const auto& v : values)
  {
    text += (first ? "" : ", ") + exact(static_cast<double>(v));
    first = false;
  }
  return text + "]";
}

// Version 3 carries the step and the config; a table that knows neither is written as version 2,
// byte for byte the file it always was.
bool knowsHowToRun(const QTable& table)
{
  return table.tau > 0.0 || !table.trained_with.empty();
}

// The configuration as a literal block, readable as the config file it is, when that reads back
// as the very text (the checksum covers every character); else one double-quoted line, which
// always does.
std::string trainedWithText(const std::string& text)
{
  YAML::Emitter block;
  block << YAML::BeginMap << YAML::Key << "trained_with" << YAML::Value << YAML::Literal << text << YAML::EndMap;
  try
  {
    // Followed by a line, as in the file: a block that ends the document loses its last line
    // break, one followed by more keeps it.
    const YAML::Node back = YAML::Load(std::string(block.c_str()) + "\n#\n")["trained_with"];
    if (back.IsScalar() && back.Scalar() == text)
    {
      const std::string emitted = block.c_str();
      return emitted.substr(emitted.find(':') + 2);
    }
  }
  catch (const YAML::Exception&)
  {
  }
  YAML::Emitter quoted;
  quoted << YAML::DoubleQuoted << text;
  return quoted.c_str();
}

[[noreturn]] void refuse(const std::string& what)
{
  throw FileError(what);
}

const YAML::Node required(const YAML::Node& root, const char* key)
{
  const YAML::Node node = root[key];
  if (!node)
    refuse(std::string("missing key '") + key + "' (the file is truncated or not a Q-table)");
  return node;
}

double readNumber(const YAML::Node& node, const std::string& where)
{
  double value;
  try
  {
    // Through the classic-locale stream, the same way it was written, so it reads back exactly.
    if (!node.IsScalar())
      throw YAML::Exception(YAML::Mark::null_mark(), "");
    std::istringstream in(node.Scalar());
    in.imbue(std::locale::classic());
    in >> value;
    if (!in || !(in >> std::ws).eof())
      throw YAML::Exception(YAML::Mark::null_mark(), "");
  }
  catch (const YAML::Exception&)
  {
    refuse(where + " is not a number");
  }
  if (!std::isfinite(value))
    refuse(where + " is not finite");
  return value;
}

std::vector<double> readNumbers(const YAML::Node& node, const std::string& where, std::size_t expected_size)
{
  if (!node.IsSequence())
    refuse(where + " is not a list");
  if (expected_size != 0 && node.size() != expected_size)
    refuse(where + " has " + std::to_string(node.size()) + " entries, expected " + std::to_string(expected_size));
  std::vector<double> values;
  for (std::size_t i = 0; i < node.size(); ++i)
    values.push_back(readNumber(node[i], where + "[" + std::to_string(i) + "]"));
  return values;
}

std::uint64_t readCount(const YAML::Node& node, const std::string& where)
{
  try
  {
    return node.as<std::uint64_t>();
  }
  catch (const YAML::Exception&)
  {
    refuse(where + " is not a whole number >= 0");
  }
}

}  // namespace

std::string formatQTable(const QTable& table)
{
  const FeatureParams& f = table.features();
  const DiscretiserParams& d = f.discretiser;
  const bool tiles = f.kind == FeatureKind::Tiles;
  std::ostringstream out;
  out << "# Q-table of cartpole_qlearning. The checksum covers every number below: edit by hand and the\n"
      << "# file will be refused.\n"
      << "format: " << kFormatName << "\n"
      << "version: " << (knowsHowToRun(table) ? kQTableFormatVersion : 2) << "\n";
  if (tiles)
    out << "# Features: tile coding. Each of the tilings is a grid of tiles over the bounds (one tile more\n"
        << "# than 'tiles' along a used dimension), tiling i displaced by i * (1, 3, 5, 7) / tilings of a\n"
        << "# tile along the used dimensions; values outside the bounds go to the edge tiles.\n"
        << "# Q(s, a) is the sum of the active tile of every tiling's value.\n"
        << "features: tiles\n"
        << "dimensions: [x, x_dot, theta, theta_dot]\n"
        << "tilings: " << f.tilings << "\n"
        << "tiles: " << flowList(f.tiles) << "\n";
  else
    out << "# Features: uniform bins per state dimension; values outside the bounds go to the end bins.\n"
        << "features: bins\n"
        << "dimensions: [x, x_dot, theta, theta_dot]\n"
        << "bins: " << flowList(d.bins) << "\n";
  out << "lower_bounds: " << flowList(d.lower) << "\n"
      << "upper_bounds: " << flowList(d.upper) << "\n";
  // Written only when on: a table without it is the file it always was.
  if (f.previous_action)
    out << "# The rows repeat once per previous action: first for none (an episode's first state), then\n"
        << "# for each action in order; the learner sees the action it took last.\n"
        << "previous_action: true\n";
  out << "# The effort [N] of each action: one column of values per action.\n"
      << "actions: " << flowList(table.actions()) << "\n";
  if (knowsHowToRun(table))
    out << "# What it takes to run it: the step it learnt [s] and the configuration that trained it.\n";
  if (table.tau > 0.0)
    out << "tau: " << exact(table.tau) << "\n";
  if (!table.trained_with.empty())
  {
    const std::string text = trainedWithText(table.trained_with);
    out << "trained_with: " << text << (text.back() == '\n' ? "" : "\n");
  }
  out << "# Training that produced this table.\n"
      << "episodes: " << table.episodes << "\n"
      << "steps: " << table.steps << "\n"
      << "rows: " << table.stateCount() << "\n"
      << "checksum: " << checksumOf(table) << "\n";
  if (tiles)
    out << "# One row per tile: tiling by tiling, and within a tiling the tiles combined in mixed radix,\n"
        << "# x most significant.\n";
  else
    out << "# One row per state: the bins combined in mixed radix, x most significant.\n";
  out << "values:\n";
  std::string text = out.str();
  text.reserve(text.size() + table.stateCount() * (8 + 26 * table.actionCount()));
  for (std::size_t s = 0; s < table.stateCount(); ++s)
  {
    text += "  - [";
    for (std::size_t a = 0; a < table.actionCount(); ++a)
    {
      if (a > 0)
        text += ", ";
      appendExact(text, table.at(s, a));
    }
    text += "]\n";
  }
  return text;
}

namespace
{
// A list of 4 whole numbers in [1, kMaxBinsPerDimension] (bins or tiles).
std::array<unsigned, kStateDimensions> readCounts(const YAML::Node& root, const char* key)
{
  const std::vector<double> counts = readNumbers(required(root, key), key, kStateDimensions);
  std::array<unsigned, kStateDimensions> values{};
  for (std::size_t i = 0; i < kStateDimensions; ++i)
  {
    if (counts[i] != std::floor(counts[i]) || counts[i] < 1 || counts[i] > kMaxBinsPerDimension)
      refuse(std::string(key) + "[" + std::to_string(i) + "] is not a whole number in [1, " +
             std::to_string(kMaxBinsPerDimension) + "]");
    values[i] = static_cast<unsigned>(counts[i]);
  }
  return values;
}
}  // namespace

namespace
{
YAML::Node loadYaml(const std::string& text)
{
  try
  {
    return YAML::Load(text);
  }
  catch (const YAML::Exception& e)
  {
    refuse(std::string("not valid YAML (corrupt or truncated): ") + e.what());
  }
}

// The rows as formatQTable writes them, a line "  - [v, v, ...]" each to the end of the text,
// read straight from it: yaml-cpp makes a node of every number (a table of 2,000,000 values took
// 40 s and 1.5 GB to load that way). nullopt when the text is laid out otherwise (by hand: other
// spacing, comments, block lists, a line cut short) or holds a number that is not finite: then
// yaml-cpp reads the whole file and says what is wrong, as it always did. Complete rows of our
// layout that are too few or too many are refused here.
std::optional<std::vector<double>> rowsAsWritten(std::string_view text, std::size_t row_count, std::size_t actions)
{
  std::vector<double> values;
  values.reserve(row_count * actions);
  const char* at = text.data();
  const char* const end = at + text.size();
  std::size_t rows = 0;
  while (at != end)
  {
    if (end - at < 5 || std::memcmp(at, "  - [", 5) != 0)
      return std::nullopt;
    at += 5;
    for (;;)
    {
      double value = 0.0;
      const std::from_chars_result read = readDouble(at, end, value);
      if (read.ec != std::errc() || !std::isfinite(value))
        return std::nullopt;
      values.push_back(value);
      at = read.ptr;
      if (at != end && *at == ']')
        break;
      if (end - at < 2 || at[0] != ',' || at[1] != ' ')
        return std::nullopt;
      at += 2;
    }
    if (end - at < 2 || at[1] != '\n')
      return std::nullopt;
    at += 2;
    ++rows;
    if (values.size() != rows * actions)
      return std::nullopt;  // yaml-cpp's reading names the row
  }
  if (rows != row_count)
    refuse("values has " + std::to_string(rows) + " rows, expected " + std::to_string(row_count) +
           " (the file is truncated or its shape is wrong)");
  return values;
}
}  // namespace

QTable parseQTable(const std::string& text)
{
  // The header (everything before the rows) through yaml-cpp, the rows as written (see
  // rowsAsWritten); a file laid out otherwise goes through yaml-cpp whole.
  const std::size_t values_at = text.rfind("\nvalues:\n");
  bool rows_apart = values_at != std::string::npos;
  YAML::Node root;
  if (rows_apart)
  {
    try
    {
      root = loadYaml(text.substr(0, values_at + 1));
    }
    catch (const FileError&)
    {
      rows_apart = false;
    }
    rows_apart = rows_apart && root.IsMap() && !root["values"];
  }
  if (!rows_apart)
    root = loadYaml(text);
  if (!root.IsMap())
    refuse("not a Q-table file (expected a YAML mapping with 'format: " + std::string(kFormatName) + "')");
  const YAML::Node format = required(root, "format");
  if (!format.IsScalar() || format.Scalar() != kFormatName)
    refuse("not a Q-table file (format is not '" + std::string(kFormatName) + "')");
  const YAML::Node version = required(root, "version");
  const bool version1 = version.IsScalar() && version.Scalar() == "1";
  const bool version3 = version.IsScalar() && version.Scalar() == "3";
  if (!version1 && !version3 && !(version.IsScalar() && version.Scalar() == "2"))
    refuse("format version " + (version.IsScalar() ? version.Scalar() : std::string("?")) +
           " is not supported (this build reads versions 1 to " + std::to_string(kQTableFormatVersion) + ")");

  // Version 1 had bins only and no 'features' key.
  FeatureParams features;
  if (!version1)
  {
    const YAML::Node kind = required(root, "features");
    if (!kind.IsScalar() || (kind.Scalar() != "bins" && kind.Scalar() != "tiles"))
      refuse("features is not 'bins' or 'tiles'");
    features.kind = featureKindFromString(kind.Scalar());
  }
  DiscretiserParams& discretiser = features.discretiser;
  if (features.kind == FeatureKind::Tiles)
  {
    const double tilings = readNumber(required(root, "tilings"), "tilings");
    if (tilings != std::floor(tilings) || tilings < 1 || tilings > kMaxTilings)
      refuse("tilings is not a whole number in [1, " + std::to_string(kMaxTilings) + "]");
    features.tilings = static_cast<unsigned>(tilings);
    features.tiles = readCounts(root, "tiles");
  }
  else
  {
    discretiser.bins = readCounts(root, "bins");
  }
  const std::vector<double> lower = readNumbers(required(root, "lower_bounds"), "lower_bounds", kStateDimensions);
  const std::vector<double> upper = readNumbers(required(root, "upper_bounds"), "upper_bounds", kStateDimensions);
  std::copy(lower.begin(), lower.end(), discretiser.lower.begin());
  std::copy(upper.begin(), upper.end(), discretiser.upper.begin());
  // Absent in older files: the state alone.
  if (const YAML::Node previous = root["previous_action"])
  {
    if (!previous.IsScalar() || (previous.Scalar() != "true" && previous.Scalar() != "false"))
      refuse("previous_action is not true or false");
    features.previous_action = previous.Scalar() == "true";
  }
  const std::string invalid = features.validate();
  if (!invalid.empty())
    refuse("invalid " + toString(features.kind) + ": " + invalid);
  const std::vector<double> actions = readNumbers(required(root, "actions"), "actions", 0);
  if (actions.empty() || actions.size() > kMaxActions)
    refuse("actions has " + std::to_string(actions.size()) + " entries (allowed: 1 to " + std::to_string(kMaxActions) +
           ")");

  // Every count is checked against the rows the file really holds before the table (up to
  // kMaxTableValues values: 160 MB) is allocated, so a short file that claims a huge table costs
  // nothing.
  const std::size_t row_count = features.rowCount(actions.size());
  if (static_cast<std::uint64_t>(row_count) * actions.size() > kMaxTableValues)
    refuse(std::to_string(row_count) + " rows of " + std::to_string(actions.size()) + " values are more than the " +
           std::to_string(kMaxTableValues) + " a table may hold");
  const char* const rows_key = version1 ? "states" : "rows";
  const std::uint64_t rows_logged = readCount(required(root, rows_key), rows_key);
  if (rows_logged != row_count)
    refuse(std::string(rows_key) + " is " + std::to_string(rows_logged) + " but the " +
           (features.kind == FeatureKind::Tiles ? "tilings and tiles" : "bins") + " give " + std::to_string(row_count));
  std::optional<std::vector<double>> values;
  if (rows_apart)
    values = rowsAsWritten(std::string_view(text).substr(values_at + 9), row_count, actions.size());
  if (!values)
  {
    if (rows_apart)
      root = loadYaml(text);
    const YAML::Node rows = required(root, "values");
    if (!rows.IsSequence())
      refuse("values is not a list of rows");
    if (rows.size() != row_count)
      refuse("values has " + std::to_string(rows.size()) + " rows, expected " + std::to_string(row_count) +
             " (the file is truncated or its shape is wrong)");
    values.emplace();
    values->reserve(row_count * actions.size());
    for (std::size_t s = 0; s < rows.size(); ++s)
    {
      const std::vector<double> row = readNumbers(rows[s], "values row " + std::to_string(s), actions.size());
      values->insert(values->end(), row.begin(), row.end());
    }
  }

  QTable table(features, actions);
  table.episodes = readCount(required(root, "episodes"), "episodes");
  table.steps = readCount(required(root, "steps"), "steps");
  if (version3)
  {
    if (const YAML::Node tau = root["tau"])
    {
      table.tau = readNumber(tau, "tau");
      if (!(table.tau > 0.0))
        refuse("tau is not > 0");
    }
    if (const YAML::Node config = root["trained_with"])
    {
      if (!config.IsScalar())
        refuse("trained_with is not a text");
      table.trained_with = config.Scalar();
    }
    if (table.tau == 0.0 && table.trained_with.empty())
      refuse("a version 3 file says tau or trained_with (or both)");
  }
  table.setValues(std::move(*values));

  const YAML::Node checksum = required(root, "checksum");
  const std::string expected = checksumOf(table);
  if (!checksum.IsScalar() || checksum.Scalar() != expected)
    refuse("checksum mismatch: the file says " + (checksum.IsScalar() ? checksum.Scalar() : std::string("?")) +
           ", its contents give " + expected + " (the file is corrupt or was edited)");
  return table;
}

std::string defaultTableDirectory(const std::string& name_space)
{
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  const std::string base = ros_home != nullptr && *ros_home != '\0'
                               ? std::string(ros_home) + "/cartpole_qlearning"
                               : std::string(home != nullptr ? home : ".") + "/.ros/cartpole_qlearning";
  if (name_space.empty() || name_space == "/")
    return base;
  return base + (name_space.front() == '/' ? "" : "/") + name_space;
}

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
  const YAML::Node root = loadYaml(head.substr(0, values_at + 1));
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
