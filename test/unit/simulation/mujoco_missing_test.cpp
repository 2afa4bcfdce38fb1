// Built as mujoco_tests in place of the MuJoCo engine's tests when CMake finds no MuJoCo (it is
// optional; Debian 11 has no libmujoco-dev): the results then count them as skipped, with the
// reason, rather than silently fewer.
#include <gtest/gtest.h>

TEST(MujocoEngineTest, SkippedBecauseThisBuildHasNoMujoco)
{
  GTEST_SKIP() << "MuJoCo was not found when this package was built (Debian 12 and 13: libmujoco-dev; "
                  "Debian 11 has none): the MuJoCo engine and its tests are off";
}
