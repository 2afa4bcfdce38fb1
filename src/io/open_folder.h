// Opening folders and files below a directory one component at a time, never through a link
// (private to src/io/: file_access.cpp and appending_file.cpp).
#pragma once

#include <string>
#include <utility>

#include <unistd.h>

namespace cartpole_qlearning
{
namespace io_internal
{
// "WHAT PATH: the system's reason".
std::string systemError(const std::string& what, const std::string& path, int error);
// Throws FileError(what): a path or file refused.
[[noreturn]] void refuse(const std::string& what);

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

// A path below a directory, opened down to the folder that holds its last component.
struct Located
{
  Descriptor folder;
  std::string name;   // the last component
  std::string shown;  // the whole path, for messages
};

// The directory, opened (made first, with the folders on the way, when missing and `create`).
// Throws FileError.
Descriptor openDirectory(const std::string& directory, bool create);

// What is at `name` in the directory, for a refusal's message.
std::string describeEntry(int directory, const std::string& name);

// Opens each folder of `relative` (checked by relativePathUnder) below the open directory
// without following links; missing folders are created when `create`. Throws FileError.
Located locate(Descriptor base, const std::string& base_path, const std::string& relative, bool create);

}  // namespace io_internal
}  // namespace cartpole_qlearning
