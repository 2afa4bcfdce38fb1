// The one translation unit of the tests that instantiates std::regex (see text_match.h for why).
#include "text_match.h"

#include <mutex>
#include <regex>
#include <unordered_map>

namespace cartpole_qlearning
{
namespace test
{
namespace text_match
{
namespace
{
// The compiled pattern, compiled once per process. The tests used to keep their patterns in static
// std::regex objects or build one per call; several call these functions line by line (a trace of
// thousands of lines, every Markdown page's lines) or every 50 ms while awaiting a node's output,
// and compiling a pattern costs far more than matching one line. The map only grows, and an
// unordered_map's elements stay where they are when it rehashes, so a reference stays valid after
// the lock is released; a const std::regex may be used from several threads at once. A pattern
// that does not compile throws here and is not kept.
const std::regex& compiled(const std::string& pattern)
{
  static std::mutex mutex;
  static std::unordered_map<std::string, std::regex> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto found = cache.find(pattern);
  if (found == cache.end())
    found = cache.emplace(pattern, std::regex(pattern)).first;  // ECMAScript, as std::regex(pattern)
  return found->second;
}

Groups groupsOf(const std::smatch& match)
{
  Groups groups;
  groups.reserve(match.size());
  for (const std::ssub_match& group : match)
    groups.push_back(group.str());
  return groups;
}
}  // namespace

bool contains(const std::string& text, const std::string& pattern, Groups* groups)
{
  std::smatch match;
  const bool found = std::regex_search(text, match, compiled(pattern));
  if (groups != nullptr)
    *groups = found ? groupsOf(match) : Groups();
  return found;
}

bool matchesWhole(const std::string& text, const std::string& pattern, Groups* groups)
{
  std::smatch match;
  const bool found = std::regex_match(text, match, compiled(pattern));
  if (groups != nullptr)
    *groups = found ? groupsOf(match) : Groups();
  return found;
}

std::vector<Groups> allMatches(const std::string& text, const std::string& pattern)
{
  std::vector<Groups> matches;
  for (std::sregex_iterator it(text.begin(), text.end(), compiled(pattern)), end; it != end; ++it)
    matches.push_back(groupsOf(*it));
  return matches;
}

std::string replaceAll(const std::string& text, const std::string& pattern, const std::string& format)
{
  return std::regex_replace(text, compiled(pattern), format);
}
}  // namespace text_match
}  // namespace test
}  // namespace cartpole_qlearning
