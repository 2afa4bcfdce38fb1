// What a rostest client tells the shared main (test/support/rostest_main.cpp, linked into every
// client by CMakeLists.txt's add_rostest_client) about the scratch folders its .test file gives it.
#pragma once

#include <string>
#include <vector>

namespace cartpole_qlearning
{
namespace test
{
// A folder for the launches, nodes and files a client starts or writes, named by the .test file
// in the test node's private parameter `param` (~q_table_dir, ~ros_home: an $(anon ...) path, so
// that runs side by side do not meet). Declared at namespace scope, it registers itself: the
// shared main removes the folder once the tests have run (and makes it first, when asked), so no
// client repeats that in a main of its own.
class ScratchFolder
{
public:
  // Who makes the folder: the nodes the .test file starts (or the tests), or the main before the
  // first test, for tests that write into it straight away.
  enum class Make
  {
    byTheTests,
    beforeTheTests,
  };

  explicit ScratchFolder(std::string param, Make make = Make::byTheTests);
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;

  // The folder ("" when the .test file sets no such parameter). Needs ros::init: call it in a test.
  std::string path() const;
  const std::string& param() const
  {
    return param_;
  }
  bool madeBeforeTheTests() const
  {
    return make_ == Make::beforeTheTests;
  }

private:
  std::string param_;
  Make make_;
};

// Every ScratchFolder of this executable, in the order they were declared.
const std::vector<const ScratchFolder*>& scratchFolders();

}  // namespace test
}  // namespace cartpole_qlearning
