#include "open_folder.h"

#include "cartpole_qlearning/io/file_access.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>

namespace cartpole_qlearning
{
namespace io_internal
{
namespace fs = std::filesystem;

void refuse(const std::string& what)
{
  throw FileError(what);
}

std::string systemError(const std::string& what, const std::string& path, int error)
{
  return what + " " + path + ": " + std::strerror(error);
}

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

}  // namespace io_internal
}  // namespace cartpole_qlearning
