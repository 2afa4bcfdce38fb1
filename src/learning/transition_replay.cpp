#include "cartpole_qlearning/learning/transition_replay.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/io/yaml_load.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
std::string knownNames(const std::vector<std::string>& names)
{
  std::string list;
  for (const std::string& name : names)
    list += (list.empty() ? "" : ", ") + name;
  return list;
}

class Parser
{
public:
  Parser(std::string origin, const std::vector<std::string>& names, std::size_t action_count)
    : origin_(std::move(origin)), names_(names), action_count_(action_count)
  {
  }

  std::vector<ReplayTransition> parse(const std::string& text) const
  {
    YAML::Node root;
    try
    {
      root = loadYaml(text);
    }
    catch (const YAML::ParserException& e)
    {
      throw ReplayError(origin_ + " line " + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
    }
    if (!root.IsMap())
      fail(root, "must be a YAML mapping with the key 'transitions'");
    for (const auto& entry : root)
    {
      if (!entry.first.IsScalar() || entry.first.Scalar() != "transitions")
        fail(entry.first, "unknown key '" + text_of(entry.first) + "' (the file holds only 'transitions')");
    }
    const YAML::Node list = root["transitions"];
    if (!list || !list.IsSequence() || list.size() == 0)
      fail(list ? list : root, "'transitions' must be a non-empty list of [state, action, reward, next state]");
    std::vector<ReplayTransition> transitions;
    for (const YAML::Node& item : list)
      transitions.push_back(transition(item));
    return transitions;
  }

private:
  ReplayTransition transition(const YAML::Node& item) const
  {
    if (!item.IsSequence() || item.size() != 4)
      fail(item, "a transition must be a list [state, action, reward, next state], not '" + text_of(item) + "'");
    for (const YAML::Node& field : item)
    {
      if (!field.IsScalar())
        fail(field, "'" + text_of(field) + "' is not allowed (each field is a name or a number)");
    }
    ReplayTransition t;
    t.line = line(item);
    t.state = state(item[0]);
    if (t.state == names_.size() - 1)
      fail(item[0],
           "'" + item[0].Scalar() + "' is the terminal state: no transition leaves it (only a next state may be it)");
    t.action = action(item[1]);
    t.reward = reward(item[2]);
    t.next_state = state(item[3]);
    t.terminal = t.next_state == names_.size() - 1;
    if (t.terminal)
      t.next_state = 0;  // the terminal state has no row
    return t;
  }

  std::size_t state(const YAML::Node& field) const
  {
    const auto it = std::find(names_.begin(), names_.end(), field.Scalar());
    if (it == names_.end())
      fail(field, "unknown state '" + field.Scalar() + "' (this config's states: " + knownNames(names_) + ")");
    return static_cast<std::size_t>(it - names_.begin());
  }

  std::size_t action(const YAML::Node& field) const
  {
    std::string digits = field.Scalar();
    if (!digits.empty() && (digits[0] == 'A' || digits[0] == 'a'))
      digits.erase(0, 1);
    const std::string allowed = "allowed: A0 .. A" + std::to_string(action_count_ - 1) + ", or 0 .. " +
                                std::to_string(action_count_ - 1) + ": this config has " +
                                std::to_string(action_count_) + " actions";
    if (digits.empty() || digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos)
      fail(field, "action '" + field.Scalar() + "' is not allowed (" + allowed + ")");
    const std::size_t index = std::stoul(digits);
    if (index >= action_count_)
      fail(field, "action '" + field.Scalar() + "' is out of range (" + allowed + ")");
    return index;
  }

  double reward(const YAML::Node& field) const
  {
    double value = 0.0;
    try
    {
      value = field.as<double>();
    }
    catch (const YAML::Exception&)
    {
      fail(field, "reward '" + field.Scalar() + "' is not a number");
    }
    if (!std::isfinite(value))
      fail(field, "reward '" + field.Scalar() + "' is not allowed (must be finite)");
    return value;
  }

  static int line(const YAML::Node& node)
  {
    return node.Mark().line + 1;
  }

  static std::string text_of(const YAML::Node& node)
  {
    if (node.IsScalar())
      return node.Scalar();
    YAML::Emitter out;
    out << YAML::Flow << node;
    return out.c_str();
  }

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const
  {
    const int at = node.Mark().line;
    throw ReplayError(origin_ + (at >= 0 ? " line " + std::to_string(at + 1) : std::string()) + ": " + what);
  }

  std::string origin_;
  const std::vector<std::string>& names_;
  std::size_t action_count_;
};
}  // namespace

std::vector<ReplayTransition> parseReplay(const std::string& text, const std::string& origin,
                                          const std::vector<std::string>& names, std::size_t action_count)
{
  if (names.size() < 2 || action_count == 0)
    throw ReplayError(origin + ": the config has no states or no actions to replay");
  return Parser(origin, names, action_count).parse(text);
}

std::vector<ReplayTransition> loadReplay(const std::string& path, const std::vector<std::string>& names,
                                         std::size_t action_count)
{
  // A replay is a page of transitions typed by hand: a few MB is far more than anyone writes, and
  // readFile refuses what is not a regular file (a FIFO would block, /dev/zero never end).
  constexpr std::uint64_t kMaxReplayBytes = std::uint64_t(16) << 20;
  std::string text;
  try
  {
    text = readFile(path, kMaxReplayBytes);
  }
  catch (const FileError& e)
  {
    throw ReplayError(e.what());
  }
  return parseReplay(text, path, names, action_count);
}

void replayTransitions(QLearningAgent& agent, const std::vector<ReplayTransition>& transitions,
                       const std::function<void(const ReplayTransition&, const TraceStep&)>& on_step,
                       const std::function<void(std::uint64_t episode)>& on_episode_end)
{
  QTable& table = agent.table();
  unsigned step_in_episode = 0;
  for (const ReplayTransition& t : transitions)
  {
    TraceStep step;
    step.episode = table.episodes + 1;
    step.step = ++step_in_episode;
    step.state = t.state;
    step.action = t.action;
    step.reward = t.reward;
    step.next_state = t.next_state;
    step.terminal = t.terminal;
    step.alpha = agent.alpha(table.episodes);
    step.gamma = agent.params().gamma;
    step.update = agent.update(t.state, t.action, t.reward, t.next_state, t.terminal, step.alpha);
    ++table.steps;
    if (on_step)
      on_step(t, step);
    if (!t.terminal)
      continue;
    ++table.episodes;
    step_in_episode = 0;
    if (on_episode_end)
      on_episode_end(step.episode);
  }
}

}  // namespace cartpole_qlearning
