// Regular expressions for the tests, behind plain functions: the tests' checks of output lines, pages
// and sources, with std::regex's ECMAScript grammar and its default flags (what the tests used to call
// directly), so a pattern means here what it meant there.
//
// Why not <regex> in each test: libstdc++'s regex is all templates, instantiated again in every
// translation unit that uses it. Measured here, one use costs a test file about 3.2 s more under
// g++ -O2 and 6.7 s more under clang-14 -O1 with ASan and UBSan, and CI builds the tests both ways
// on 2 cores. text_match.cpp is the only file that includes <regex>: built once as a static
// library (cartpole_qlearning_test_text), linked into the tests that match text. No ROS here.
#pragma once

#include <string>
#include <vector>

namespace cartpole_qlearning
{
namespace test
{
namespace text_match
{
// One match's groups: [0] the whole match, [n] group n of the pattern ("" for a group that took no
// part in the match, as std::smatch's str() gives).
using Groups = std::vector<std::string>;

// A bad pattern throws std::regex_error (a std::runtime_error) from every function, as
// std::regex's constructor does.

// Whether some part of text matches pattern (std::regex_search). On a match, *groups (when given)
// holds the first match's groups; otherwise it is left empty.
bool contains(const std::string& text, const std::string& pattern, Groups* groups = nullptr);

// Whether all of text matches pattern (std::regex_match). On a match, *groups (when given) holds
// its groups; otherwise it is left empty.
bool matchesWhole(const std::string& text, const std::string& pattern, Groups* groups = nullptr);

// Every match of pattern in text, left to right, each by its groups (std::sregex_iterator).
std::vector<Groups> allMatches(const std::string& text, const std::string& pattern);

// text with every match of pattern replaced by format, in which $1, $2... stand for the groups
// and $& for the match (std::regex_replace, ECMAScript format rules).
std::string replaceAll(const std::string& text, const std::string& pattern, const std::string& format);
}  // namespace text_match
}  // namespace test
}  // namespace cartpole_qlearning
