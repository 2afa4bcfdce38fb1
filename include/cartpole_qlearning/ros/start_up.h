// Starting a node class, for the executables' mains and the nodelets alike.
#pragma once

#include <functional>
#include <string>

namespace cartpole_qlearning
{
// Runs start() (which constructs the node class) and returns true. When it throws (a bad
// parameter, an unusable table file), logs the reason as FATAL on the logger `name`, and, when
// roslaunch started this process, ends that launch: under roslaunch the node may respawn, and
// would fail the same way forever. Returns false then, with the reason in *reason when given.
bool startNode(const std::string& name, const std::function<void()>& start, std::string* reason = nullptr);

}  // namespace cartpole_qlearning
