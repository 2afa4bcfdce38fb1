// Ending the roslaunch that started this process, the way Ctrl-C does.
//
// ROS 1 offers a node one way to end its launch: be `required` and exit, which roslaunch
// reports as a crash ("REQUIRED process ... has died!") and which rules out `respawn`. The
// training nodes respawn after a crash instead, and when training is done the controller ends
// the launch with this: roslaunch then stops every node (each saves what it must) and exits 0.
#pragma once

#include <string>

namespace cartpole_qlearning
{
// True when this process (or, for a nodelet, its manager) was started by roslaunch: its parent
// runs roslaunch. rostest, rosrun and a shell are not roslaunch.
bool startedByRoslaunch();

// Sends SIGINT to the parent roslaunch and returns true; returns false (and sends nothing) when
// the parent is not roslaunch.
bool endParentLaunch();

}  // namespace cartpole_qlearning
