#include "cartpole_qlearning/io/appending_file.h"

#include "open_folder.h"

#include "cartpole_qlearning/io/file_access.h"

#include <cerrno>
#include <filesystem>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace cartpole_qlearning
{
namespace fs = std::filesystem;
using namespace io_internal;

namespace
{
// Opens `name` in the open folder for appending; a FIFO or device planted under the name is
// refused without blocking on it.
Descriptor openForAppending(const Descriptor& folder, const std::string& name, const std::string& shown,
                            bool refuse_links)
{
  Descriptor fd(::openat(folder.get(), name.c_str(),
                         O_RDWR | O_APPEND | O_CREAT | O_NONBLOCK | O_CLOEXEC | (refuse_links ? O_NOFOLLOW : 0), 0644));
  if (fd.get() < 0)
  {
    const int error = errno;
    if (error == ELOOP && refuse_links)
      refuse("cannot open " + shown + ": it is a symbolic link (refused: no symbolic links here)");
    refuse(systemError("cannot open", shown, error));
  }
  struct stat status;
  if (::fstat(fd.get(), &status) != 0)
    refuse(systemError("cannot open", shown, errno));
  if (!S_ISREG(status.st_mode))
    refuse("cannot open " + shown + ": not a regular file");
  ::fcntl(fd.get(), F_SETFL, O_APPEND);
  return fd;
}
}  // namespace

AppendingFile::AppendingFile(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}

AppendingFile::AppendingFile(AppendingFile&& other) noexcept
  : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_))
{
}

AppendingFile& AppendingFile::operator=(AppendingFile&& other) noexcept
{
  std::swap(fd_, other.fd_);
  std::swap(path_, other.path_);
  return *this;
}

AppendingFile::~AppendingFile()
{
  if (fd_ >= 0)
    ::close(fd_);
}

AppendingFile AppendingFile::openUnder(const std::string& directory, const std::string& path)
{
  const std::string relative = relativePathUnder(directory, path);
  const std::string base = fs::absolute(directory).lexically_normal().string();
  const Located at = locate(openDirectory(base, true), base, relative, true);
  return AppendingFile(openForAppending(at.folder, at.name, at.shown, true).release(), at.shown);
}

AppendingFile AppendingFile::open(const std::string& path)
{
  const fs::path target(path);
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..")
    refuse("cannot open " + path + ": it names a directory");
  const std::string folder = target.has_parent_path() ? target.parent_path().string() : ".";
  return AppendingFile(openForAppending(openDirectory(folder, true), target.filename().string(), path, false).release(),
                       path);
}

std::string AppendingFile::read(std::uint64_t max_bytes) const
{
  std::string text;
  char buffer[65536];
  for (;;)
  {
    const ssize_t n = ::pread(fd_, buffer, sizeof buffer, static_cast<off_t>(text.size()));
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0)
      refuse(systemError("cannot read", path_, errno));
    if (n == 0)
      return text;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > max_bytes)
      refuse(path_ + ": more than " + std::to_string(max_bytes) + " bytes");
  }
}

void AppendingFile::truncate(std::uint64_t size)
{
  if (::ftruncate(fd_, static_cast<off_t>(size)) != 0)
    refuse(systemError("cannot shorten", path_, errno));
}

void AppendingFile::append(const std::string& text)
{
  std::size_t written = 0;
  while (written < text.size())
  {
    const ssize_t n = ::write(fd_, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0)
      refuse(systemError("cannot write", path_, errno));
    written += static_cast<std::size_t>(n);
  }
}

}  // namespace cartpole_qlearning
