// Ending the roslaunch that started this process, the way Ctrl-C does.
//
// ROS 1 offers a node one way to end its launch: be `required` and exit, which roslaunch
// reports as a crash ("REQUIRED process ... has died!") and which rules out `respawn`. The
// training nodes respawn after a crash instead, and when training is done the controller ends
// the launch with this: roslaunch then stops every node (each saves what it must) and exits 0.
#pragma once

#include <sys/types.h>

namespace cartpole_qlearning
{
// True when this process (or, for a nodelet, its manager) was started by roslaunch: its parent
// runs roslaunch, or an ancestor up to 4 levels up (a launch-prefix such as gdb or xterm in
// between). rostest, rosrun and a shell are not roslaunch. (A node on a remote machine finds
// the roslaunch child that runs there: ending it ends that host's part of the launch.)
bool startedByRoslaunch();
// Its pid, or 0.
pid_t launchingRoslaunch();

// Sends SIGINT to that roslaunch and returns true; returns false (and sends nothing) when there
// is none.
bool endParentLaunch();

}  // namespace cartpole_qlearning
