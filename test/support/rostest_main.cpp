// The main of every rostest client (cartpole_add_rostest_client in CMakeLists.txt links it): the gtests run
// as one ROS node, then the scratch folders the client declared (rostest_main.h) are removed.
#include "rostest_main.h"

#include <ros/ros.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <system_error>
#include <utility>

namespace cartpole_qlearning
{
namespace test
{
namespace
{
std::vector<const ScratchFolder*>& registry()
{
  // Function-local: the clients' ScratchFolders register during static initialisation, in an
  // order across files that C++ leaves open.
  static std::vector<const ScratchFolder*> folders;
  return folders;
}
}  // namespace

ScratchFolder::ScratchFolder(std::string param, Make make) : param_(std::move(param)), make_(make)
{
  registry().push_back(this);
}

std::string ScratchFolder::path() const
{
  std::string folder;
  ros::param::get("~" + param_, folder);
  return folder;
}

const std::vector<const ScratchFolder*>& scratchFolders()
{
  return registry();
}

}  // namespace test
}  // namespace cartpole_qlearning

int main(int argc, char** argv)
{
  namespace fs = std::filesystem;
  using cartpole_qlearning::test::scratchFolders;
  ::testing::InitGoogleTest(&argc, argv);
  // The node's name: the executable's, which is the client's (rostest renames it after the .test
  // file's test-name all the same).
  ros::init(argc, argv, fs::path(argv[0]).filename().string());
  // The node started once for the whole run: the tests' own handles come and go, and the last of
  // them going would shut it down.
  ros::NodeHandle keep_node_up;
  for (const auto* folder : scratchFolders())
    if (folder->madeBeforeTheTests() && !folder->path().empty())
      fs::create_directories(folder->path());
  const int result = RUN_ALL_TESTS();
  for (const auto* folder : scratchFolders())
  {
    std::error_code ignored;  // a folder the tests never made, or made read-only, fails no test
    if (!folder->path().empty())
      fs::remove_all(folder->path(), ignored);
  }
  return result;
}
