// The gtest entry point, written out because catkin's catkin_add_gtest links gtest without
// its main on both Noetic and Debian's catkin.
#include <gtest/gtest.h>

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
