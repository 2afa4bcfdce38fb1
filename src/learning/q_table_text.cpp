#include "cartpole_qlearning/learning/q_table_file.h"

#include "q_table_document.h"

#include "cartpole_qlearning/io/number_text.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace cartpole_qlearning
{
namespace q_table_document
{
namespace
{
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
}  // namespace

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
  if (tiles && f.hasSecondTiles())
  {
    sum.add(std::uint64_t{2});
    for (const unsigned t : f.second_tiles)
      sum.add(static_cast<std::uint64_t>(t));
  }
  if (tiles && f.hasEnergyTiles())
  {
    sum.add(std::uint64_t{4});
    for (const unsigned t : f.energy_tiles)
      sum.add(static_cast<std::uint64_t>(t));
    sum.add(f.pole_frequency);
  }
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
}  // namespace q_table_document

namespace
{
using q_table_document::checksumOf;
using q_table_document::kFormatName;

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
  // Written only when present: a table without it is the file it always was.
  if (tiles && f.hasSecondTiles())
    out << "# A second tile coding, as many tilings again over the same bounds with these tiles; its rows\n"
        << "# follow the first's, and Q(s, a) sums the active tile of every tiling of both.\n"
        << "second_tiles: " << flowList(f.second_tiles) << "\n";
  if (tiles && f.hasEnergyTiles())
    out << "# A tile coding over the swing, as many tilings again over (x, x_dot, the pole's energy relative\n"
        << "# to upright's per m g l: cos(theta) - 1 + (theta_dot / pole_frequency)^2 / 2, in [-2, 2],\n"
        << "# theta_dot * cos(theta) within +-upper_bounds[3]) with these tiles; its rows follow the others'.\n"
        << "energy_tiles: " << flowList(f.energy_tiles) << "\n"
        << "pole_frequency: " << exact(f.pole_frequency) << "\n";
  if (!tiles)
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
}  // namespace cartpole_qlearning
