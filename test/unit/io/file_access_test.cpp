// Paths under the table directory (no "..", no symbolic links, nothing written outside) and
// atomic saves (a process killed mid-save leaves the old file or the new one, whole).
#include "cartpole_qlearning/io/file_access.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
class FileAccessTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("file_access_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "tables");
    tables_ = (dir_ / "tables").string();
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  static void write(const fs::path& file, const std::string& text)
  {
    std::ofstream(file) << text;
  }
  // Every file below the test directory, as "relative/path".
  std::vector<std::string> files() const
  {
    return test::filesBelow(dir_);
  }

  // A file beside q.yaml in tables/: a save's temporary file.
  bool temporaryFileThere() const
  {
    std::error_code error;
    for (fs::directory_iterator it(dir_ / "tables", error), end; !error && it != end; it.increment(error))
    {
      if (it->path().filename() != "q.yaml")
        return true;
    }
    return false;
  }

  fs::path dir_;
  std::string tables_;
};

TEST_F(FileAccessTest, RelativePathsResolveUnderTheDirectory)
{
  const std::string base = fs::weakly_canonical(tables_).string();
  EXPECT_EQ(base + "/q.yaml", resolvePathUnder(tables_, "q.yaml"));
  EXPECT_EQ(base + "/runs/q.yaml", resolvePathUnder(tables_, "runs/./q.yaml"));
  EXPECT_EQ(base + "/abs.yaml", resolvePathUnder(tables_, base + "/abs.yaml"));
  EXPECT_EQ("runs/q.yaml", relativePathUnder(tables_, base + "/runs/q.yaml"));
}

TEST_F(FileAccessTest, AFileWithATrailingSlashIsSaidToNameAFolderAndAFoldersSlashesGo)
{
  try
  {
    relativePathUnder(tables_, "runs/x/");
    ADD_FAILURE() << "a trailing slash taken for a file";
  }
  catch (const FileError& e)
  {
    EXPECT_EQ("runs/x/ ends in '/': it names a folder, not a file", std::string(e.what()));
  }
  // Tab completion's slashes, on a folder: the same folder.
  EXPECT_EQ("runs/x", withoutTrailingSlashes("runs/x/"));
  EXPECT_EQ("runs/x", withoutTrailingSlashes("runs/x//"));
  EXPECT_EQ("runs/x", withoutTrailingSlashes("runs/x"));
  EXPECT_EQ("/", withoutTrailingSlashes("/"));
  EXPECT_EQ("/", withoutTrailingSlashes("//"));
  EXPECT_EQ("", withoutTrailingSlashes(""));
}

// roslaunch passes q_table_dir:=~/tables on as it is: the nodes expand "~" as a shell would.
TEST(ExpandHome, ATildeAloneOrFollowedByASlashIsTheHome)
{
  EXPECT_EQ("/home/ada", expandHome("~", "/home/ada"));
  EXPECT_EQ("/home/ada/tables/q.yaml", expandHome("~/tables/q.yaml", "/home/ada"));
  // Anything else is a name like any other: relative, absolute, or "~" inside or later on.
  EXPECT_EQ("~ada/tables", expandHome("~ada/tables", "/home/ada"));
  EXPECT_EQ("tables/~/q.yaml", expandHome("tables/~/q.yaml", "/home/ada"));
  EXPECT_EQ("/tmp/~", expandHome("/tmp/~", "/home/ada"));
  EXPECT_EQ("", expandHome("", "/home/ada"));
  // Without a home a path that needs one is refused, not taken as a folder named "~".
  EXPECT_EQ("q.yaml", expandHome("q.yaml", ""));
  EXPECT_THROW(expandHome("~/tables", ""), FileError);
}

TEST_F(FileAccessTest, ASavedFileHasTheModeTheUsersUmaskGives)
{
  const auto mode_of = [](const fs::path& file) {
    struct stat status
    {
    };
    EXPECT_EQ(0, ::stat(file.c_str(), &status)) << file;
    return status.st_mode & 07777;
  };
  const mode_t old_mask = ::umask(077);
  writeFileUnder(tables_, "private.yaml", "a: 1\n");
  writeFileAtomically((dir_ / "private_too.yaml").string(), "a: 1\n");
  ::umask(022);
  writeFileUnder(tables_, "shared.yaml", "a: 1\n");
  ::umask(old_mask);
  EXPECT_EQ(0600u, mode_of(dir_ / "tables" / "private.yaml"));
  EXPECT_EQ(0600u, mode_of(dir_ / "private_too.yaml"));
  EXPECT_EQ(0644u, mode_of(dir_ / "tables" / "shared.yaml"));
}

TEST_F(FileAccessTest, ACommandLineSaveThroughALinkWritesItsTargetAndKeepsTheLink)
{
  // latest.yaml -> runs/today.yaml (relative), and an absolute link to a file not there yet.
  fs::create_directories(dir_ / "runs");
  write(dir_ / "runs" / "today.yaml", "old\n");
  fs::create_symlink("runs/today.yaml", dir_ / "latest.yaml");
  fs::create_symlink(dir_ / "runs" / "new.yaml", dir_ / "next.yaml");
  writeFileAtomically((dir_ / "latest.yaml").string(), "new\n");
  writeFileAtomically((dir_ / "next.yaml").string(), "made\n");
  EXPECT_TRUE(fs::is_symlink(dir_ / "latest.yaml"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "next.yaml"));
  EXPECT_EQ("new\n", readFile((dir_ / "runs" / "today.yaml").string()));
  EXPECT_EQ("made\n", readFile((dir_ / "runs" / "new.yaml").string()));
  // A link into a folder that is not there (a drive not mounted) fails as > would; nothing is
  // made on the way.
  fs::create_symlink(dir_ / "unmounted" / "q.yaml", dir_ / "on_usb.yaml");
  EXPECT_THROW(writeFileAtomically((dir_ / "on_usb.yaml").string(), "x\n"), FileError);
  EXPECT_FALSE(fs::exists(dir_ / "unmounted"));
  // A loop of links is refused with a message, not followed for ever.
  fs::create_symlink("loop_b", dir_ / "loop_a");
  fs::create_symlink("loop_a", dir_ / "loop_b");
  EXPECT_THROW(writeFileAtomically((dir_ / "loop_a").string(), "x\n"), FileError);
}

TEST_F(FileAccessTest, PathsLeavingTheDirectoryAreRefusedBeforeAnythingIsTouched)
{
  for (const std::string& escape :
       {std::string("../q.yaml"), std::string("a/../../q.yaml"), std::string("runs/x/../q.yaml"),
        std::string("nope/../out/q.yaml"), std::string("/etc/passwd"), (dir_ / "tables2" / "q.yaml").string(),
        std::string(".."), std::string("."), std::string("runs/"), std::string("")})
  {
    EXPECT_THROW(relativePathUnder(tables_, escape), FileError) << escape;
    EXPECT_THROW(writeFileUnder(tables_, escape, "x"), FileError) << escape;
    EXPECT_THROW(readFileUnder(tables_, escape), FileError) << escape;
  }
  EXPECT_EQ(std::vector<std::string>{}, files());
}

TEST_F(FileAccessTest, SymbolicLinksAnywhereBelowTheDirectoryAreRefusedAndNothingIsWrittenOutside)
{
  write(dir_ / "secret.yaml", "outside");
  // A link to a directory outside, one to a directory inside (it could be changed at any
  // moment), and one to a file outside.
  fs::create_directory_symlink(dir_, dir_ / "tables" / "out");
  fs::create_directories(dir_ / "tables" / "runs");
  fs::create_directory_symlink(dir_ / "tables" / "runs", dir_ / "tables" / "alias");
  fs::create_symlink(dir_ / "secret.yaml", dir_ / "tables" / "runs" / "link.yaml");
  const auto before = files();

  for (const std::string& path :
       {std::string("out/secret.yaml"), std::string("out/new.yaml"), std::string("alias/q.yaml"),
        std::string("runs/link.yaml"), std::string("out/tables/runs/q.yaml"),
        (dir_ / "tables" / "out" / "secret.yaml").string()})
  {
    try
    {
      writeFileUnder(tables_, path, "written");
      ADD_FAILURE() << path << " was written";
    }
    catch (const FileError& e)
    {
      EXPECT_NE(std::string::npos, std::string(e.what()).find("symbolic link")) << path << ": " << e.what();
    }
    EXPECT_THROW(readFileUnder(tables_, path), FileError) << path;
  }
  EXPECT_EQ(before, files());
  EXPECT_EQ("outside", readFile((dir_ / "secret.yaml").string()));
  // The directory itself may be reached through a link of the user's choosing.
  fs::create_directory_symlink(dir_ / "tables", dir_ / "chosen");
  writeFileUnder((dir_ / "chosen").string(), "runs/new/q.yaml", "fine");
  EXPECT_EQ("fine", readFileUnder(tables_, "runs/new/q.yaml"));
}

TEST_F(FileAccessTest, MissingDirectoriesAreCreatedAndAFileInTheWayIsReported)
{
  const std::string fresh = (dir_ / "fresh" / "deep").string();
  writeFileUnder(fresh, "runs/a/b.yaml", "text");
  EXPECT_EQ("text", readFileUnder(fresh, "runs/a/b.yaml"));
  write(dir_ / "tables" / "blocker", "a file");
  EXPECT_THROW(writeFileUnder(tables_, "blocker/q.yaml", "x"), FileError);
  fs::create_directories(dir_ / "tables" / "folder");
  EXPECT_THROW(writeFileUnder(tables_, "folder", "x"), FileError);
  EXPECT_THROW(readFileUnder(tables_, "folder"), FileError);
  EXPECT_THROW(readFileUnder(tables_, "missing.yaml"), FileError);
}

TEST_F(FileAccessTest, AFifoOrAnOversizedFileIsRefusedWithoutHanging)
{
  ASSERT_EQ(0, ::mkfifo((dir_ / "tables" / "pipe.yaml").c_str(), 0644));
  try
  {
    readFileUnder(tables_, "pipe.yaml");
    ADD_FAILURE() << "a FIFO was read";
  }
  catch (const FileError& e)
  {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("not a regular file")) << e.what();
  }
  write(dir_ / "tables" / "big.yaml", std::string(100, 'x'));
  EXPECT_THROW(readFileUnder(tables_, "big.yaml", 99), FileError);
  EXPECT_EQ(100u, readFileUnder(tables_, "big.yaml", 100).size());
}

TEST_F(FileAccessTest, TemporaryFilesOfWritersThatDiedAreRemovedByTheNextSave)
{
  // pid_max is at most 2^22 on Linux: no process has pid 999999999. This process is alive.
  const fs::path dead = dir_ / "tables" / ".q.yaml.tmp.999999999.0";
  const fs::path alive = dir_ / "tables" / (".q.yaml.tmp." + std::to_string(::getpid() + 0) + ".77");
  const fs::path other = dir_ / "tables" / ".other.yaml.tmp.999999999.0";
  write(dead, "left by a kill -9");
  write(alive, "being written");
  write(other, "another file's");
  writeFileUnder(tables_, "q.yaml", "new");
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));
}

TEST_F(FileAccessTest, AProcessKilledMidSaveLeavesTheOldFileOrTheNewOneWhole)
{
  // Large versions, so that a kill at a random moment mostly lands inside a write or an fsync.
  const std::string path = (dir_ / "tables" / "q.yaml").string();
  const auto version = [](char c) { return "version " + std::string(1, c) + "\n" + std::string(8 << 20, c); };
  writeFileAtomically(path, version('a'));
  std::mt19937 random(7);
  int interrupted = 0;
  constexpr int kTrials = 12;
  for (int trial = 0; trial < kTrials; ++trial)
  {
    int started[2];
    ASSERT_EQ(0, ::pipe(started));
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0)
    {
      // Built once: the child's time goes into saving them, not into making them.
      const std::string b = version('b');
      const std::string c = version('c');
      const char ready = 'r';
      if (::write(started[1], &ready, 1) != 1)
        ::_exit(1);
      for (bool odd = false;; odd = !odd)
        writeFileAtomically(path, odd ? c : b);
    }
    ::close(started[1]);
    // The random pause counts from when the child starts saving: on a loaded machine the fork
    // and the two versions alone outlast it, and a kill before any save proves nothing. Then the
    // kill waits for a save under way (its temporary file there): about a third of each save's
    // cycle is its rename and the folder's fsync, where a kill interrupts nothing.
    char ready = 0;
    pollfd from_child{started[0], POLLIN, 0};
    const bool started_saving = ::poll(&from_child, 1, 60000) == 1 && ::read(started[0], &ready, 1) == 1;
    ::close(started[0]);
    if (started_saving)
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(20 + random() % 180));
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      while (!temporaryFileThere() && std::chrono::steady_clock::now() < give_up)
        std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(started_saving) << "trial " << trial << ": the child did not start saving within 60 s";
    const std::string text = readFile(path);
    ASSERT_GT(text.size(), 8u) << "trial " << trial << ": the file is cut short: " << text.size() << " bytes";
    ASSERT_EQ(version(text.at(8)), text) << "trial " << trial << ": the file is not one whole version";
    // A temporary file left behind: this kill interrupted a save.
    for (const auto& entry : fs::directory_iterator(dir_ / "tables"))
    {
      if (entry.path().filename() != "q.yaml")
      {
        ++interrupted;
        fs::remove(entry.path());
      }
    }
  }
  // Otherwise the test proved nothing: every kill fell between two saves.
  EXPECT_GT(interrupted, kTrials / 3) << "only " << interrupted << " of " << kTrials << " kills landed mid-save";
}

}  // namespace
