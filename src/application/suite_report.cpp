#include "cartpole_qlearning/application/suite_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace cartpole_qlearning
{
double shownReturn(double value, int decimals)
{
  const double scale = std::pow(10.0, decimals);
  // + 0.0 turns -0.0 into 0.0 (IEEE 754 rounding to nearest).
  return std::round(value * scale) / scale + 0.0;
}

bool SuiteResult::passed() const
{
  return !stoppedEarly() && std::all_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.passed(); });
}

bool SuiteResult::failed() const
{
  return std::any_of(cases.begin(), cases.end(),
                     [](const CaseResult& c) { return c.balanced + (c.episodes - c.run) < c.pass; });
}

bool SuiteResult::complete() const
{
  return !stoppedEarly() && std::none_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.cutShort(); });
}

bool SuiteResult::reachedTargets() const
{
  return !stoppedEarly() &&
         std::all_of(cases.begin(), cases.end(), [](const CaseResult& c) { return c.reachedTarget(); });
}

std::uint64_t SuiteResult::worstBalanced() const
{
  std::uint64_t worst = std::numeric_limits<std::uint64_t>::max();
  for (const CaseResult& c : cases)
    worst = std::min(worst, c.balanced);
  return cases.empty() ? 0 : worst;
}

std::string SuiteResult::summary() const
{
  std::string text;
  for (const CaseResult& c : cases)
  {
    text += (text.empty() ? "" : ", ") + c.name + " " + std::to_string(c.balanced) + "/" + std::to_string(c.run);
    if (c.cutShort())
      text += " (stopped at " + std::to_string(c.run) + " of " + std::to_string(c.episodes) + ": " +
              (c.decidedAgainst() == c.pass
                   ? (c.passed() ? "passes" : "fails")
                   : (c.reachedTarget() ? "reached " : "cannot reach ") + std::to_string(c.decidedAgainst())) +
              ")";
  }
  text += std::string(": ") + (passed() ? "PASSED" : failed() ? "FAILED" : "not decided");
  if (stoppedEarly())
    text += " (stopped at " + (cases.empty() ? std::string("the start") : cases.back().name) + ", " +
            std::to_string(cases_in_suite - cases.size()) + " of " + std::to_string(cases_in_suite) + " cases not run)";
  return text;
}

std::size_t SuiteResult::casesPassed() const
{
  return static_cast<std::size_t>(
      std::count_if(cases.begin(), cases.end(), [](const CaseResult& c) { return c.passed(); }));
}

std::string SuiteResult::table() const
{
  return rows() + summary();
}

std::string SuiteResult::rows() const
{
  std::size_t width = 4;
  for (const CaseResult& c : cases)
    width = std::max(width, c.name.size());
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-*s  %8s  %6s  %11s  %s\n", static_cast<int>(width), "case", "balanced", "needed",
                "mean return", "verdict");
  out << line;
  for (const CaseResult& c : cases)
  {
    const std::string balanced = std::to_string(c.balanced) + "/" + std::to_string(c.run);
    // A case cut short says after how many of its episodes its verdict was known.
    const std::string verdict =
        std::string(c.passed() ? "pass" : "FAIL") +
        (c.cutShort() ? " (decided after " + std::to_string(c.run) + " of " + std::to_string(c.episodes) + ")" : "");
    std::snprintf(line, sizeof line, "%-*s  %8s  %6llu  %11.1f  %s\n", static_cast<int>(width), c.name.c_str(),
                  balanced.c_str(), static_cast<unsigned long long>(c.pass), shownReturn(c.mean_return, 1),
                  verdict.c_str());
    out << line;
  }
  if (!reward_note.empty())
    out << "(mean return: " << reward_note << ")\n";
  return out.str();
}
}  // namespace cartpole_qlearning
