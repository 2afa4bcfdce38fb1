#include "cartpole_qlearning/io/yaml_load.h"

#include <algorithm>

namespace cartpole_qlearning
{
namespace
{
YAML::Mark markAt(const std::string& text, std::size_t at)
{
  YAML::Mark mark = YAML::Mark::null_mark();
  mark.pos = static_cast<int>(at);
  mark.line = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  const std::size_t line_start = at == 0 ? std::string::npos : text.rfind('\n', at - 1);
  mark.column = static_cast<int>(line_start == std::string::npos ? at : at - line_start - 1);
  return mark;
}

bool isSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}
}  // namespace

std::optional<YAML::Mark> flowColonOldYamlCppLoopsOn(const std::string& text)
{
  int depth = 0;         // open [ and { (the flow context)
  char quote = '\0';     // inside '...' or "..."
  bool comment = false;  // from '#' to the end of the line
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    const char c = text[i];
    // Where a scalar may begin: a quote there opens a quoted one, a '#' there a comment (a quote
    // or '#' inside a plain scalar, as in "it's" or "a#b", is part of it).
    const bool scalar_start =
        i == 0 || isSpace(text[i - 1]) || std::string("[{,").find(text[i - 1]) != std::string::npos;
    if (comment)
    {
      comment = c != '\n' && c != '\r';
    }
    else if (quote != '\0')
    {
      if (quote == '"' && c == '\\')
        ++i;  // the escaped character
      else if (c == quote)
        quote = '\0';  // ('' inside '...' closes and reopens it: the same state either way)
    }
    else if (c == '#' && (i == 0 || isSpace(text[i - 1])))
    {
      comment = true;
    }
    else if ((c == '\'' || c == '"') && scalar_start)
    {
      quote = c;
    }
    else if (c == '[' || c == '{')
    {
      ++depth;
    }
    else if ((c == ']' || c == '}') && depth > 0)
    {
      --depth;
    }
    else if (c == ':' && depth > 0 && (i + 1 == text.size() || text[i + 1] == ']'))
    {
      return markAt(text, i);
    }
  }
  return std::nullopt;
}

YAML::Node loadYaml(const std::string& text)
{
#ifdef CARTPOLE_YAML_CPP_LOOPS_ON_FLOW_COLON
  if (const auto mark = flowColonOldYamlCppLoopsOn(text))
    throw YAML::ParserException(*mark,
                                "a ':' ending an entry of a flow collection ([...] or {...}), which "
                                "yaml-cpp before 0.7 never returns from (jbeder/yaml-cpp#499)");
#endif
  return YAML::Load(text);
}

bool loadYamlGuardsFlowColons()
{
#ifdef CARTPOLE_YAML_CPP_LOOPS_ON_FLOW_COLON
  return true;
#else
  return false;
#endif
}

}  // namespace cartpole_qlearning
