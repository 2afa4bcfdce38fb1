#include "cartpole_qlearning/learning/trace.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace cartpole_qlearning
{
std::vector<std::string> stateNames(const AgentParams& params)
{
  if (!params.state_names.empty())
    return params.state_names;
  const std::size_t states = Discretiser(params.discretiser).stateCount();
  std::vector<std::string> names;
  // With previous_action the rows repeat per previous action: none first, then each action.
  const std::size_t blocks = params.featureParams().blocks(params.actions.size());
  names.reserve(states * blocks + 1);
  for (std::size_t b = 0; b < blocks; ++b)
  {
    const std::string after =
        blocks == 1 ? "" : (b == 0 ? " at start" : " after " + traceNumber(params.actions[b - 1]));
    for (std::size_t s = 0; s < states; ++s)
      names.push_back("S" + std::to_string(s) + after);
  }
  names.push_back("fallen");
  return names;
}

std::string traceNumber(double value)
{
  char text[32];
  // +0.0 for -0.0: a reader sees no sign on a zero.
  std::snprintf(text, sizeof text, "%.12g", value == 0.0 ? 0.0 : value);
  return text;
}

namespace
{
// A number inside arithmetic: "(-0.25)", so that "1.6525 - (-0.25)" reads as written by hand.
std::string operand(double value)
{
  const std::string text = traceNumber(value);
  return text.front() == '-' ? "(" + text + ")" : text;
}
}  // namespace

std::string actionName(std::size_t action, const std::vector<double>& efforts)
{
  char effort[32];
  std::snprintf(effort, sizeof effort, "%+g", action < efforts.size() ? efforts[action] : 0.0);
  return "A" + std::to_string(action) + " (" + effort + " N)";
}

std::string traceLine(const TraceStep& t, const std::vector<std::string>& names, const std::vector<double>& efforts)
{
  const std::string& state = names.at(t.state);
  const std::string next =
      t.terminal ? names.back() + " (terminal)" : names.at(t.next_state) + (t.truncated ? " (truncated)" : "");
  const std::string action = "A" + std::to_string(t.action);
  const QUpdate& u = t.update;
  std::ostringstream line;
  line << "episode " << t.episode << " step " << t.step << ": " << state << " --" << actionName(t.action, efforts)
       << "--> " << next << ", r = " << traceNumber(t.reward) << "; target = ";
  if (t.terminal)
    line << traceNumber(u.target) << " (no future)";
  else
    line << traceNumber(t.reward) << " + " << operand(t.gamma) << " * " << operand(u.next_max) << " = "
         << traceNumber(u.target);
  line << "; Q(" << state << ", " << action << ") = " << traceNumber(u.old_value) << " + " << operand(t.alpha) << " * ("
       << traceNumber(u.target) << " - " << operand(u.old_value) << ") = " << traceNumber(u.new_value);
  return line.str();
}

std::string qTableText(const QTable& table, const std::vector<std::string>& names)
{
  std::size_t name_width = 5;  // "state"
  for (const std::string& name : names)
    name_width = std::max(name_width, name.size());
  const std::size_t column_width = 16;
  const auto cell = [&](const std::string& text, std::size_t width) {
    return text + std::string(width > text.size() ? width - text.size() : 1, ' ');
  };
  std::string text = "  " + cell("state", name_width + 2);
  for (std::size_t a = 0; a < table.actionCount(); ++a)
    text += cell(actionName(a, table.actions()), column_width);
  const auto row = [&](const std::string& name, const std::vector<double>& values, const std::string& note) {
    std::string line = "  " + cell(name, name_width + 2);
    for (const double value : values)
      line += cell(traceNumber(value), column_width);
    line += note;
    while (!line.empty() && line.back() == ' ')
      line.pop_back();
    return line;
  };
  while (!text.empty() && text.back() == ' ')
    text.pop_back();
  std::vector<double> values(table.actionCount());
  for (std::size_t s = 0; s < table.stateCount(); ++s)
  {
    for (std::size_t a = 0; a < table.actionCount(); ++a)
      values[a] = table.at(s, a);
    text += "\n" + row(names.at(s), values, "");
  }
  text += "\n" + row(names.back(), std::vector<double>(table.actionCount(), 0.0), "(terminal: no future, Q = 0)");
  return text;
}

}  // namespace cartpole_qlearning
