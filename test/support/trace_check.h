// Reads the trace as a learner reads it (the printed lines and tables, not the learner's memory)
// and redoes its arithmetic: shared by the tests of train_headless and of the controller.
#pragma once

#include "text_match.h"

#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
namespace test
{
struct TracedUpdate
{
  unsigned long episode = 0, step = 0;
  std::string state, next;
  std::size_t action = 0;
  bool terminal = false;
  std::string reward, gamma, next_max, target, old_value, alpha, new_value;  // as printed
};

struct TracedTable
{
  std::string title;                                     // "episode 1", "transition 10 (the end of the replay)"
  std::map<std::string, std::vector<std::string>> rows;  // by state name, values as printed
};

// "(-0.25)" -> "-0.25": the trace puts negative operands in parentheses.
inline std::string bare(const std::string& text)
{
  return text.size() > 2 && text.front() == '(' && text.back() == ')' ? text.substr(1, text.size() - 2) : text;
}

inline double number(const std::string& text)
{
  return std::strtod(bare(text).c_str(), nullptr);
}

// The trace's update lines and tables, in order, from any text holding them (a log prefixes
// each line with its own header; a table's rows are the lines after its title).
class TraceReading
{
public:
  TraceReading(const std::string& text, const std::vector<std::string>& names) : names_(names)
  {
    static const std::string update =
        "episode ([0-9]+) step ([0-9]+): (.+) --A([0-9]+) \\([^)]*\\)--> (.+?)( \\(terminal\\)| \\(truncated\\))?, "
        "r = (\\S+); target = (?:(\\S+) \\+ (\\S+) \\* (\\S+) = (\\S+)|(\\S+) \\(no future\\)); "
        "Q\\((.+), A([0-9]+)\\) = (\\S+) \\+ (\\S+) \\* \\((\\S+) - (\\S+)\\) = (\\S+)$";
    static const std::string title = "Q-table after (.*):$";
    std::istringstream in(text);
    std::string line;
    TracedTable* table = nullptr;
    static const std::string colour = "\x1b\\[[0-9;]*m";  // rosconsole's, around each message
    while (std::getline(in, line))
    {
      line = text_match::replaceAll(line, colour, "");
      text_match::Groups m;
      if (table != nullptr && readRow(line, *table))
        continue;
      table = nullptr;
      if (text_match::contains(line, update, &m))
      {
        TracedUpdate u;
        u.episode = std::stoul(m[1]);
        u.step = std::stoul(m[2]);
        u.state = m[3];
        u.action = std::stoul(m[4]);
        u.next = m[5];
        u.terminal = m[6] == " (terminal)";
        u.reward = m[7];
        u.gamma = bare(m[9]);
        u.next_max = bare(m[10]);
        // Groups 8 and 11 are (\S+), never empty when they take part: empty means the other branch matched.
        u.target = !m[11].empty() ? m[11] : m[12];
        if (m[13] != u.state || std::stoul(m[14]) != u.action || m[15] != bare(m[18]) || m[17] != u.target)
          errors.push_back("a line whose parts disagree: " + line);
        u.old_value = m[15];
        u.alpha = bare(m[16]);
        u.new_value = m[19];
        if (!m[8].empty() && m[8] != u.reward)
          errors.push_back("target's reward is not the step's: " + line);
        updates.push_back(u);
        order.push_back('u');
      }
      else if (text_match::contains(line, title, &m))
      {
        tables.push_back(TracedTable{m[1], {}});
        table = &tables.back();
        order.push_back('t');
      }
    }
  }

  // Replays the printed updates on a table of zeros and checks every line: its old value is the
  // value the trace last gave that pair, max Q(next) is the largest of the next state's row,
  // target = r + gamma * max Q(next) (r alone into the terminal state), new = old + alpha *
  // (target - old); and each table printed equals the values traced so far. Returns the
  // failures, one line each.
  std::vector<std::string> check(std::size_t actions, double gamma, double alpha) const
  {
    std::vector<std::string> failures = errors;
    std::map<std::string, std::vector<std::string>> q;
    for (std::size_t s = 0; s + 1 < names_.size(); ++s)
      q[names_[s]] = std::vector<std::string>(actions, "0");
    const auto near = [](double a, double b) { return std::fabs(a - b) <= 1e-9 * (1.0 + std::fabs(a) + std::fabs(b)); };
    std::size_t next_update = 0, next_table = 0;
    for (const char kind : order)
    {
      if (kind == 't')
      {
        const TracedTable& t = tables[next_table++];
        for (const auto& row : q)
        {
          const auto found = t.rows.find(row.first);
          if (found == t.rows.end() || found->second != row.second)
            failures.push_back("the table after " + t.title + " differs from the trace at " + row.first);
        }
        const auto terminal = t.rows.find(names_.back());
        if (terminal == t.rows.end() || terminal->second != std::vector<std::string>(actions, "0"))
          failures.push_back("the table after " + t.title + " lacks the terminal state's zeros");
        continue;
      }
      const TracedUpdate& u = updates[next_update++];
      const std::string where = "episode " + std::to_string(u.episode) + " step " + std::to_string(u.step) + ": ";
      if (q.count(u.state) == 0 || u.action >= actions || (!u.terminal && q.count(u.next) == 0) ||
          (u.terminal && u.next != names_.back()))
      {
        failures.push_back(where + "unknown state or action");
        continue;
      }
      std::string& value = q[u.state][u.action];
      if (u.old_value != value)
        failures.push_back(where + "old " + u.old_value + " but the trace last gave " + value);
      if (!near(number(u.alpha), alpha))
        failures.push_back(where + "alpha " + u.alpha);
      const double r = number(u.reward);
      if (u.terminal)
      {
        if (!near(number(u.target), r))
          failures.push_back(where + "a terminal target " + u.target + " is not the reward " + u.reward);
      }
      else
      {
        double max = -INFINITY;
        for (const std::string& v : q[u.next])
          max = std::max(max, number(v));
        if (number(u.next_max) != max)
          failures.push_back(where + "max Q(next) " + u.next_max + " is not the row's largest");
        if (!near(number(u.gamma), gamma))
          failures.push_back(where + "gamma " + u.gamma);
        if (!near(number(u.target), r + gamma * max))
          failures.push_back(where + "target " + u.target + " is not r + gamma * max Q(next)");
      }
      const double old = number(u.old_value);
      if (!near(number(u.new_value), old + alpha * (number(u.target) - old)))
        failures.push_back(where + "new " + u.new_value + " is not old + alpha * (target - old)");
      value = u.new_value;
    }
    return failures;
  }

  std::vector<TracedUpdate> updates;
  std::vector<TracedTable> tables;
  std::vector<char> order;          // 'u' an update, 't' a table, as printed
  std::vector<std::string> errors;  // lines that do not hold together

private:
  bool readRow(const std::string& line, TracedTable& table) const
  {
    for (const std::string& name : names_)
    {
      if (line.rfind("  " + name + "  ", 0) != 0)
        continue;
      std::istringstream values(line.substr(2 + name.size()));
      std::vector<std::string>& row = table.rows[name];
      std::string v;
      while (values >> v && v.front() != '(')
        row.push_back(v);
      return true;
    }
    return line.rfind("  state ", 0) == 0;  // the header
  }

  std::vector<std::string> names_;
};

}  // namespace test
}  // namespace cartpole_qlearning
