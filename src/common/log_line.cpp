#include "cartpole_qlearning/common/log_line.h"

#include <cstdio>

namespace cartpole_qlearning
{
std::string formatTextV(const char* pattern, std::va_list args)
{
  std::va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, pattern, args);
  std::string text(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size > 0)
    std::vsnprintf(text.data(), text.size() + 1, pattern, again);
  va_end(again);
  return text;
}

std::string formatText(const char* pattern, ...)
{
  std::va_list args;
  va_start(args, pattern);
  std::string text = formatTextV(pattern, args);
  va_end(args);
  return text;
}

}  // namespace cartpole_qlearning
