// Reading and writing the package's files safely.
//
// Writes are atomic and durable: a temporary file beside the target, written, flushed to disk,
// renamed over the target, and the directory flushed, so a crash at any moment (kill -9, power
// loss) leaves either the old file whole or the new one whole.
//
// Paths that users give over services or launch arguments are taken under a directory and
// opened component by component relative to it (openat with O_NOFOLLOW): no symbolic link is
// followed anywhere below the directory and ".." is refused, with no gap between a check and
// the open in which a link could be swapped in.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace cartpole_qlearning
{
// Anything wrong with a path or a file; the message says what, and nothing was changed.
class FileError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// The largest file read: a table of the most states allowed is written in well under this.
constexpr std::uint64_t kMaxFileBytes = std::uint64_t(1) << 30;

// "~" and "~/..." stand for `home` (the caller passes $HOME), as a shell would have expanded
// them: roslaunch hands `q_table_dir:=~/tables` to a node as it is, and the literal folder "~"
// it would otherwise make lies in the node's working directory. Any other path is returned as
// it is ("~name" too: other users' homes are not looked up). Throws FileError when the path
// needs a home and `home` is empty.
std::string expandHome(const std::string& path, const std::string& home);

// Checks a user-given path lexically and returns it relative to the directory: a relative path
// is taken from the directory; an absolute one must lie inside it; ".." components, an empty
// path and the directory itself are refused. The directory is the user's own choice (links in
// it are fine). Throws FileError. Touches no file.
std::string relativePathUnder(const std::string& directory, const std::string& path);

// A folder's path without the trailing slashes tab completion adds ("runs/x/" -> "runs/x"; "/"
// stays): the same folder, for the paths joined to it and for relativePathUnder.
std::string withoutTrailingSlashes(const std::string& folder);

// relativePathUnder, joined to the directory's absolute form: what messages show.
std::string resolvePathUnder(const std::string& directory, const std::string& path);

// A file that says at its beginning how long it can be (a table's header gives its rows and
// actions): given the first kHeadBytes of a file longer than that, the most bytes the file may
// have, or a FileError when the beginning is not what it should be. The rest is not read when the
// file is longer: a huge file is refused at the cost of its head.
constexpr std::uint64_t kHeadBytes = std::uint64_t(1) << 20;
using SizeFromHead = std::function<std::uint64_t(const std::string& head)>;

// The whole file `path` (relative, below the directory), refusing symbolic links on the way,
// anything but a regular file, files over max_bytes and files over what their head claims
// (size_from_head, when given). Throws FileError.
std::string readFileUnder(const std::string& directory, const std::string& path,
                          std::uint64_t max_bytes = kMaxFileBytes, const SizeFromHead& size_from_head = {});

// Writes `text` atomically to `path` below the directory, creating the directory and any
// missing folders on the way (never through a symbolic link). Throws FileError.
void writeFileUnder(const std::string& directory, const std::string& path, const std::string& text);

// Makes the folder `path` below the directory (and the folders on the way, never through a
// link); false when something of that name exists already. Throws FileError.
bool makeDirectoryUnder(const std::string& directory, const std::string& path);

// The same for a path of the caller's own (a command-line argument): links are followed as the
// shell would. Throws FileError.
std::string readFile(const std::string& path, std::uint64_t max_bytes = kMaxFileBytes,
                     const SizeFromHead& size_from_head = {});
void writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace cartpole_qlearning
