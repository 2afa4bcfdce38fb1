// A file that grows a line at a time (a learning curve), for a reader that follows it.
#pragma once

#include "cartpole_qlearning/io/file_access.h"

#include <cstdint>
#include <string>

namespace cartpole_qlearning
{
// A file kept open to add lines to, one write per line: a reader following the file sees each
// line whole as soon as it is written (a log, not a table: no temporary file, no rename).
class AppendingFile
{
public:
  // `path` below the directory, taken as writeFileUnder takes it (missing folders made, no link
  // followed). Created when missing. Throws FileError.
  static AppendingFile openUnder(const std::string& directory, const std::string& path);
  // A path of the caller's own: links followed as the shell would; missing folders made.
  static AppendingFile open(const std::string& path);

  AppendingFile(AppendingFile&&) noexcept;
  AppendingFile& operator=(AppendingFile&&) noexcept;
  ~AppendingFile();

  // What the file holds now (at most max_bytes). Throws FileError.
  std::string read(std::uint64_t max_bytes = kMaxFileBytes) const;
  // Cuts the file to its first `size` bytes. Throws FileError.
  void truncate(std::uint64_t size);
  // Adds `text` at the end. Throws FileError.
  void append(const std::string& text);
  // The path as opened, for messages.
  const std::string& path() const
  {
    return path_;
  }

private:
  AppendingFile(int fd, std::string path);
  int fd_ = -1;
  std::string path_;
};

}  // namespace cartpole_qlearning
