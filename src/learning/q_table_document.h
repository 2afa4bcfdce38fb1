// The Q-table document's parts that its writer (q_table_text.cpp), its reader
// (q_table_parse.cpp) and the file's size check (q_table_file.cpp) share: the format's name, the
// checksum and the readers of a value that refuse what is wrong (private to src/learning/).
#pragma once

#include "cartpole_qlearning/learning/q_table.h"

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
namespace q_table_document
{
constexpr const char* kFormatName = "cartpole_qlearning/q_table";

// The checksum of every number that defines the table ("fnv1a64:<16 hex digits>").
std::string checksumOf(const QTable& table);

// Throws FileError(what): the file is refused.
[[noreturn]] void refuse(const std::string& what);
// The text as YAML, or a refusal saying it is not.
YAML::Node loadTableYaml(const std::string& text);
// root[key], or a refusal naming the missing key.
const YAML::Node required(const YAML::Node& root, const char* key);
// A finite number, read back exactly as the writer wrote it; `where` names it in a refusal.
double readNumber(const YAML::Node& node, const std::string& where);
// A list of numbers (expected_size of them, unless 0).
std::vector<double> readNumbers(const YAML::Node& node, const std::string& where, std::size_t expected_size);
std::uint64_t readCount(const YAML::Node& node, const std::string& where);

}  // namespace q_table_document
}  // namespace cartpole_qlearning
