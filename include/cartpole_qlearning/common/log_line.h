// What the core says, as values: the controller node logs each line on its named logger (with
// its prefix, added in one place), train_headless prints it. The core decides the words; the
// callers only carry them out.
#pragma once

#include <cstdarg>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// One line to say, without any "qlearning_controller: " prefix.
struct LogLine
{
  enum class Level
  {
    Info,
    Warn,
    Error
  };
  Level level = Level::Info;
  std::string text;
  // false: said as it is, with no prefix (the progress lines and the trace: the same lines
  // train_headless prints).
  bool prefixed = true;
};
using LogLines = std::vector<LogLine>;

// printf into a std::string (the format is checked by the compiler).
__attribute__((format(printf, 1, 2))) std::string formatText(const char* pattern, ...);
std::string formatTextV(const char* pattern, std::va_list args);

}  // namespace cartpole_qlearning
