#include "cartpole_qlearning/io/file_access.h"

#include "open_folder.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

namespace cartpole_qlearning
{
namespace fs = std::filesystem;
using namespace io_internal;

namespace
{
std::string readOpenFile(const Descriptor& fd, const std::string& shown, std::uint64_t max_bytes,
                         const SizeFromHead& size_from_head)
{
  struct stat status;
  if (::fstat(fd.get(), &status) != 0)
    refuse(systemError("cannot read", shown, errno));
  if (!S_ISREG(status.st_mode))
    refuse("cannot read " + shown + ": not a regular file");
  // Opened non-blocking so that a FIFO could not hang the open; a file reads as usual.
  const int flags = ::fcntl(fd.get(), F_GETFL);
  if (flags >= 0)
    ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK);
  if (static_cast<std::uint64_t>(status.st_size) > max_bytes)
    refuse(shown + ": " + std::to_string(status.st_size) + " bytes, more than this file may have (" +
           std::to_string(max_bytes) + ")");
  std::string text;
  char buffer[65536];
  // A file longer than its head is held to the size its head claims before the rest is read.
  bool head_judged = !size_from_head || static_cast<std::uint64_t>(status.st_size) <= kHeadBytes;
  for (;;)
  {
    if (!head_judged && text.size() >= kHeadBytes)
    {
      head_judged = true;
      std::uint64_t claimed = 0;
      try
      {
        claimed = size_from_head(text.substr(0, kHeadBytes));
      }
      catch (const FileError& e)
      {
        refuse(shown + ": " + e.what());
      }
      if (static_cast<std::uint64_t>(status.st_size) > claimed)
        refuse(shown + ": " + std::to_string(status.st_size) +
               " bytes, more than its own beginning says it can have (" + std::to_string(claimed) + ")");
      max_bytes = std::min(max_bytes, claimed);
    }
    const ssize_t n = ::read(fd.get(), buffer, sizeof buffer);
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0)
      refuse(systemError("cannot read", shown, errno));
    if (n == 0)
      return text;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > max_bytes)  // it grew while being read
      refuse(shown + ": more than " + std::to_string(max_bytes) + " bytes");
  }
}

// Temporary files ".<name>.tmp.<pid>.<n>" left by a writer killed mid-save (its pid gone).
void removeStaleTemporaries(const Descriptor& folder, const std::string& name)
{
  const int fd = ::openat(folder.get(), ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    return;
  DIR* entries = ::fdopendir(fd);
  if (entries == nullptr)
  {
    ::close(fd);
    return;
  }
  const std::string prefix = "." + name + ".tmp.";
  std::vector<std::string> stale;
  while (const dirent* entry = ::readdir(entries))
  {
    const std::string file = entry->d_name;
    if (file.compare(0, prefix.size(), prefix) != 0)
      continue;
    const long pid = std::strtol(file.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && pid != ::getpid() && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
      stale.push_back(file);
  }
  ::closedir(entries);
  for (const std::string& file : stale)
    ::unlinkat(folder.get(), file.c_str(), 0);
}

// Atomic, durable replacement of `name` in the open folder by `text`.
void replaceIn(const Descriptor& folder, const std::string& name, const std::string& shown, const std::string& text,
               bool refuse_links)
{
  struct stat status;
  if (::fstatat(folder.get(), name.c_str(), &status, AT_SYMLINK_NOFOLLOW) == 0)
  {
    if (S_ISDIR(status.st_mode))
      refuse("cannot save to " + shown + ": it is a directory");
    if (refuse_links && S_ISLNK(status.st_mode))
      refuse("cannot save to " + shown + ": it is a symbolic link (refused: no symbolic links here)");
  }

  removeStaleTemporaries(folder, name);
  // A name of our own beside the target: the pid and a counter keep concurrent writers apart,
  // O_EXCL makes sure nothing already there (a planted link) is opened instead.
  static std::atomic<unsigned> counter{0};
  std::string temp;
  Descriptor fd;
  for (int attempt = 0; attempt < 100 && fd.get() < 0; ++attempt)
  {
    temp = "." + name + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
    fd = Descriptor(::openat(folder.get(), temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
    if (fd.get() < 0 && errno != EEXIST)
      refuse(systemError("cannot create a temporary file beside", shown, errno));
  }
  if (fd.get() < 0)
    refuse(systemError("cannot create a temporary file beside", shown, EEXIST));
  const auto fail = [&](const std::string& what) {
    const int error = errno;
    ::unlinkat(folder.get(), temp.c_str(), 0);
    refuse(systemError(what, shown, error));
  };
  std::size_t written = 0;
  while (written < text.size())
  {
    const ssize_t n = ::write(fd.get(), text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0)
      fail("cannot write the temporary file for");
    written += static_cast<std::size_t>(n);
  }
  // The data must be on disk before the rename makes it the file; else a crash could leave an
  // empty file under the final name.
  // (Its mode is 0644 less the umask, as any new file's: a user's umask 077 keeps tables private.)
  if (::fsync(fd.get()) != 0 || fd.close() != 0)
    fail("cannot flush the temporary file for");
  if (::renameat(folder.get(), temp.c_str(), folder.get(), name.c_str()) != 0)
    fail("cannot rename the temporary file to");
  // And the rename itself durable.
  ::fsync(folder.get());
}
}  // namespace

std::string expandHome(const std::string& path, const std::string& home)
{
  if (path != "~" && path.rfind("~/", 0) != 0)
    return path;
  if (home.empty())
    refuse("cannot expand " + path + ": HOME is not set");
  return home + path.substr(1);
}

std::string relativePathUnder(const std::string& directory, const std::string& path)
{
  if (path.empty())
    refuse("the path is empty");
  std::error_code ec;
  const fs::path base = fs::absolute(directory, ec).lexically_normal();
  if (ec)
    refuse("cannot resolve directory " + directory + ": " + ec.message());
  const std::string outside = " (refused: paths must stay inside " + base.string() + ")";
  const fs::path given(path);
  // No "..": resolving it means following whatever the components before it are.
  for (const fs::path& part : given)
  {
    if (part == "..")
      refuse(path + " contains '..'" + outside);
  }
  fs::path relative = given.lexically_normal();
  if (given.is_absolute())
  {
    relative = relative.lexically_relative(base);
    if (relative.empty() || *relative.begin() == "..")
      refuse(path + " is outside " + base.string() + outside);
  }
  if (relative.empty() || relative == ".")
    refuse(path + " names the directory " + base.string() + " itself, not a file in it");
  if (relative.filename().empty() || relative.filename() == ".")
    refuse(path + " ends in '/': it names a folder, not a file");
  return relative.string();
}

std::string withoutTrailingSlashes(const std::string& folder)
{
  const std::size_t end = folder.find_last_not_of('/');
  return end == std::string::npos ? folder.substr(0, 1) : folder.substr(0, end + 1);
}

std::string resolvePathUnder(const std::string& directory, const std::string& path)
{
  const std::string relative = relativePathUnder(directory, path);
  return (fs::absolute(directory).lexically_normal() / relative).string();
}

std::string readFileUnder(const std::string& directory, const std::string& path, std::uint64_t max_bytes,
                          const SizeFromHead& size_from_head)
{
  const std::string relative = relativePathUnder(directory, path);
  const std::string base = fs::absolute(directory).lexically_normal().string();
  const Located at = locate(openDirectory(base, false), base, relative, false);
  // O_NONBLOCK: a FIFO planted under the name must not hang the caller.
  Descriptor fd(::openat(at.folder.get(), at.name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0)
  {
    const int error = errno;
    if (error == ELOOP)
      refuse("cannot open " + at.shown + ": it is a symbolic link (refused: no symbolic links below " + base + ")");
    refuse(systemError("cannot open", at.shown, error));
  }
  return readOpenFile(fd, at.shown, max_bytes, size_from_head);
}

void writeFileUnder(const std::string& directory, const std::string& path, const std::string& text)
{
  const std::string relative = relativePathUnder(directory, path);
  const std::string base = fs::absolute(directory).lexically_normal().string();
  const Located at = locate(openDirectory(base, true), base, relative, true);
  replaceIn(at.folder, at.name, at.shown, text, true);
}

bool makeDirectoryUnder(const std::string& directory, const std::string& path)
{
  const std::string relative = relativePathUnder(directory, path);
  const std::string base = fs::absolute(directory).lexically_normal().string();
  const Located at = locate(openDirectory(base, true), base, relative, true);
  if (::mkdirat(at.folder.get(), at.name.c_str(), 0755) == 0)
    return true;
  if (errno == EEXIST)
    return false;
  refuse(systemError("cannot create directory", at.shown, errno));
}

std::string readFile(const std::string& path, std::uint64_t max_bytes, const SizeFromHead& size_from_head)
{
  Descriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0)
    refuse(systemError("cannot open", path, errno));
  return readOpenFile(fd, path, max_bytes, size_from_head);
}

void writeFileAtomically(const std::string& path, const std::string& text)
{
  // A link at the name is followed, as the shell's `>` would: the file it points to gets the
  // text (made if missing) and the link stays. Replacing the link itself would cut it loose.
  fs::path target(path);
  std::error_code ec;
  for (int hops = 0; fs::is_symlink(fs::symlink_status(target, ec)); ++hops)
  {
    if (hops == 40)
      refuse("cannot save to " + path + ": too many levels of symbolic links");
    const fs::path link = fs::read_symlink(target, ec);
    if (ec)
      refuse("cannot save to " + path + ": cannot read the link " + target.string() + ": " + ec.message());
    target = link.is_absolute() ? link : target.parent_path() / link;
  }
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..")
    refuse("cannot save to " + path + ": it names a directory");
  const std::string folder = target.has_parent_path() ? target.parent_path().string() : ".";
  // Missing folders are made for the name given, not for a link's target: a link into a drive
  // not mounted fails as the shell's > would, instead of saving beside the mount point.
  replaceIn(openDirectory(folder, target.string() == path), target.filename().string(),
            target.string() == path ? path : path + " (" + target.string() + ")", text, false);
}

}  // namespace cartpole_qlearning
