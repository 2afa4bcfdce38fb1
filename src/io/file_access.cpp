#include "cartpole_qlearning/io/file_access.h"

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

namespace
{
[[noreturn]] void refuse(const std::string& what)
{
  throw FileError(what);
}

std::string systemError(const std::string& what, const std::string& path, int error)
{
  return what + " " + path + ": " + std::strerror(error);
}

// A file descriptor, closed when it goes out of scope.
class Descriptor
{
public:
  explicit Descriptor(int fd = -1) : fd_(fd) {}
  ~Descriptor()
  {
    if (fd_ >= 0)
      ::close(fd_);
  }
  Descriptor(Descriptor&& other) noexcept : fd_(other.fd_)
  {
    other.fd_ = -1;
  }
  Descriptor& operator=(Descriptor&& other) noexcept
  {
    std::swap(fd_, other.fd_);
    return *this;
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const
  {
    return fd_;
  }
  // Hands the descriptor over to the caller, who closes it.
  int release()
  {
    return std::exchange(fd_, -1);
  }
  // Closes now, reporting the error a deferred write may only show here.
  int close()
  {
    const int result = ::close(fd_);
    fd_ = -1;
    return result;
  }

private:
  int fd_;
};

Descriptor openDirectory(const std::string& directory, bool create)
{
  Descriptor fd(::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0 && errno == ENOENT && create)
  {
    std::error_code ec;
    fs::create_directories(directory, ec);
    if (ec)
      refuse("cannot create directory " + directory + ": " + ec.message());
    fd = Descriptor(::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  }
  if (fd.get() < 0)
    refuse(systemError("cannot open directory", directory, errno));
  return fd;
}

// What is at `name` in the directory, for a refusal's message.
std::string describeEntry(int directory, const std::string& name)
{
  struct stat status;
  if (::fstatat(directory, name.c_str(), &status, AT_SYMLINK_NOFOLLOW) != 0)
    return std::strerror(errno);
  if (S_ISLNK(status.st_mode))
    return "is a symbolic link";
  if (S_ISDIR(status.st_mode))
    return "is a directory";
  if (!S_ISREG(status.st_mode))
    return "is not a regular file";
  return "is a file";
}

// A path below a directory, opened down to the folder that holds its last component.
struct Located
{
  Descriptor folder;
  std::string name;   // the last component
  std::string shown;  // the whole path, for messages
};

// Opens each folder of `relative` (checked by relativePathUnder) below the open directory
// without following links; missing folders are created when `create`.
Located locate(Descriptor base, const std::string& base_path, const std::string& relative, bool create)
{
  Located located;
  located.shown = (fs::path(base_path) / relative).string();
  const std::string outside = " (refused: no symbolic links below " + base_path + ")";
  std::vector<std::string> parts;
  for (const fs::path& part : fs::path(relative))
    parts.push_back(part.string());
  located.folder = std::move(base);
  fs::path walked(base_path);
  for (std::size_t i = 0; i + 1 < parts.size(); ++i)
  {
    const std::string& part = parts[i];
    walked /= part;
    int fd = ::openat(located.folder.get(), part.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0 && errno == ENOENT && create)
    {
      if (::mkdirat(located.folder.get(), part.c_str(), 0755) != 0 && errno != EEXIST)
        refuse(systemError("cannot create directory", walked.string(), errno));
      fd = ::openat(located.folder.get(), part.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    }
    if (fd < 0)
    {
      const int error = errno;
      if (error == ELOOP || error == ENOTDIR)
      {
        const std::string what = describeEntry(located.folder.get(), part);
        refuse(located.shown + ": " + walked.string() + " " + what +
               (what == "is a symbolic link" ? outside : ", not a folder"));
      }
      refuse(systemError("cannot open directory", walked.string(), error));
    }
    located.folder = Descriptor(fd);
  }
  located.name = parts.back();
  return located;
}

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
