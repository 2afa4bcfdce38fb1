#include "cartpole_qlearning/learning/q_table_file.h"

#include "q_table_document.h"

#include "cartpole_qlearning/io/number_text.h"
#include "cartpole_qlearning/io/yaml_count.h"
#include "cartpole_qlearning/io/yaml_load.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <locale>
#include <optional>
#include <sstream>
#include <string_view>

namespace cartpole_qlearning
{
namespace q_table_document
{
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
    return yamlCount(node);
  }
  catch (const YAML::Exception&)
  {
    refuse(where + " is not a whole number >= 0");
  }
}

YAML::Node loadTableYaml(const std::string& text)
{
  try
  {
    return loadYaml(text);
  }
  catch (const YAML::Exception& e)
  {
    refuse(std::string("not valid YAML (corrupt or truncated): ") + e.what());
  }
}

}  // namespace q_table_document

using namespace q_table_document;

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

namespace
{
// The document: its root and, when its rows are laid out as formatQTable writes them, where they
// start (read apart from yaml-cpp, see rowsAsWritten).
struct Document
{
  YAML::Node root;
  bool rows_apart = false;
  std::size_t values_at = std::string::npos;
  bool version1 = false;
  bool version3 = false;
};

// The header (everything before the rows) through yaml-cpp, the rows left as written; a file laid
// out otherwise goes through yaml-cpp whole. Refuses another format or version.
Document readHeader(const std::string& text)
{
  Document doc;
  doc.values_at = text.rfind("\nvalues:\n");
  doc.rows_apart = doc.values_at != std::string::npos;
  if (doc.rows_apart)
  {
    try
    {
      doc.root = loadTableYaml(text.substr(0, doc.values_at + 1));
    }
    catch (const FileError&)
    {
      doc.rows_apart = false;
    }
    doc.rows_apart = doc.rows_apart && doc.root.IsMap() && !doc.root["values"];
  }
  if (!doc.rows_apart)
    doc.root = loadTableYaml(text);
  const YAML::Node& root = doc.root;
  if (!root.IsMap())
    refuse("not a Q-table file (expected a YAML mapping with 'format: " + std::string(kFormatName) + "')");
  const YAML::Node format = required(root, "format");
  if (!format.IsScalar() || format.Scalar() != kFormatName)
    refuse("not a Q-table file (format is not '" + std::string(kFormatName) + "')");
  const YAML::Node version = required(root, "version");
  doc.version1 = version.IsScalar() && version.Scalar() == "1";
  doc.version3 = version.IsScalar() && version.Scalar() == "3";
  if (!doc.version1 && !doc.version3 && !(version.IsScalar() && version.Scalar() == "2"))
    refuse("format version " + (version.IsScalar() ? version.Scalar() : std::string("?")) +
           " is not supported (this build reads versions 1 to " + std::to_string(kQTableFormatVersion) + ")");
  return doc;
}

// Which features number the rows, with their parameters (version 1 had bins only and no
// 'features' key).
FeatureParams readFeatures(const YAML::Node& root, bool version1)
{
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
    // Absent in older files and in tables of one tile coding.
    if (root["second_tiles"])
      features.second_tiles = readCounts(root, "second_tiles");
    if (root["energy_tiles"])
    {
      features.energy_tiles = readCounts(root, "energy_tiles");
      features.pole_frequency = readNumber(required(root, "pole_frequency"), "pole_frequency");
    }
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
  return features;
}

// The rows' values, row after row: read as written when they are, else through yaml-cpp (the
// whole document then, in doc.root).
std::vector<double> readValues(Document& doc, const std::string& text, std::size_t row_count, std::size_t actions)
{
  std::optional<std::vector<double>> values;
  if (doc.rows_apart)
    values = rowsAsWritten(std::string_view(text).substr(doc.values_at + 9), row_count, actions);
  if (values)
    return std::move(*values);
  if (doc.rows_apart)
    doc.root = loadTableYaml(text);
  const YAML::Node rows = required(doc.root, "values");
  if (!rows.IsSequence())
    refuse("values is not a list of rows");
  if (rows.size() != row_count)
    refuse("values has " + std::to_string(rows.size()) + " rows, expected " + std::to_string(row_count) +
           " (the file is truncated or its shape is wrong)");
  std::vector<double> read;
  read.reserve(row_count * actions);
  for (std::size_t s = 0; s < rows.size(); ++s)
  {
    const std::vector<double> row = readNumbers(rows[s], "values row " + std::to_string(s), actions);
    read.insert(read.end(), row.begin(), row.end());
  }
  return read;
}

// The training that produced the table and, in version 3, what it takes to run it.
void readTraining(const YAML::Node& root, bool version3, QTable& table)
{
  table.episodes = readCount(required(root, "episodes"), "episodes");
  table.steps = readCount(required(root, "steps"), "steps");
  if (!version3)
    return;
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
}  // namespace

QTable parseQTable(const std::string& text)
{
  Document doc = readHeader(text);
  const FeatureParams features = readFeatures(doc.root, doc.version1);
  const std::vector<double> actions = readNumbers(required(doc.root, "actions"), "actions", 0);
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
  const char* const rows_key = doc.version1 ? "states" : "rows";
  const std::uint64_t rows_logged = readCount(required(doc.root, rows_key), rows_key);
  if (rows_logged != row_count)
    refuse(std::string(rows_key) + " is " + std::to_string(rows_logged) + " but the " +
           (features.kind == FeatureKind::Tiles ? "tilings and tiles" : "bins") + " give " + std::to_string(row_count));
  std::vector<double> values = readValues(doc, text, row_count, actions.size());

  QTable table(features, actions);
  readTraining(doc.root, doc.version3, table);
  table.setValues(std::move(values));

  const YAML::Node checksum = required(doc.root, "checksum");
  const std::string expected = checksumOf(table);
  if (!checksum.IsScalar() || checksum.Scalar() != expected)
    refuse("checksum mismatch: the file says " + (checksum.IsScalar() ? checksum.Scalar() : std::string("?")) +
           ", its contents give " + expected + " (the file is corrupt or was edited)");
  return table;
}

}  // namespace cartpole_qlearning
