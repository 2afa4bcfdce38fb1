// Starting a node class, for the executables' mains and the nodelets alike, and the logger each
// node instance logs on.
#pragma once

#include "cartpole_qlearning/common/log_line.h"

#include <ros/console.h>

#include <functional>
#include <string>

namespace cartpole_qlearning
{
// The logger of one node instance (ROS_*_NAMED's name, under ros.cartpole_qlearning): its type,
// then its name with dots for slashes ("cartpole_sim", "/robot_1/cartpole_sim" ->
// "cartpole_sim.robot_1.cartpole_sim"), so that two sims in one manager log apart and a level
// set on ros.cartpole_qlearning.cartpole_sim still reaches every sim.
std::string nodeLogger(const std::string& type, const std::string& node_name);

// One line on a logger named as above (under ros.cartpole_qlearning), at its level. Not
// ROS_*_NAMED or NODELET_* (which expands to it): their call site keeps the logger it first met, a
// static per line of code (ros/ros_comm#561), so a second sim in the same manager would log on the
// first one's and a level set for one instance would reach the other. Here every logger name gets
// its own place (ros_conversions_test's NodeLogger test).
void logLine(const std::string& logger, ros::console::Level level, const std::string& text);
void logLine(const std::string& logger, LogLine::Level level, const std::string& text);
// A line's text as the node says it: after the node's prefix unless the line asks for none.
std::string withPrefix(const std::string& prefix, const LogLine& line);

// Runs start() (which constructs the node class) and returns true. When it throws (a bad
// parameter, an unusable table file), logs the reason as FATAL, "type: reason", on the logger
// nodeLogger(type, node_name), and, when roslaunch started this process, ends that launch: under
// roslaunch the node may respawn, and would fail the same way forever. Returns false then, with
// the reason in *reason when given.
// end_launch false: the failure is only reported (a check of the parameters, below, must not end
// the roslaunch that asked for it).
bool startNode(const std::string& type, const std::string& node_name, const std::function<void()>& start,
               std::string* reason = nullptr, bool end_launch = true);

// True when the command line asks the executable only to check its parameters
// (--check-parameters, as scripts/check_launch runs it before a launch starts): the flag is taken
// out of argv, so that ros::init sees the rest. The node then reads its parameters, opens what it
// would open, exits 1 with its FATAL line when it would refuse them, else 0.
bool takeCheckFlag(int& argc, char** argv);

// For the executables that send the robot a last zero: SIGINT and SIGTERM (Ctrl-C, roslaunch's
// kill) are only noted (ros::init must be given NoSigintHandler); spinUntilStopped spins the global
// queue every period_s until ROS shuts down or such a signal came, then, when one came or
// always_stop, calls stop() while ROS still runs, gives what it sent a moment to leave on the
// publishers' connections (which ros::shutdown closes) and shuts ROS down.
void noteStopSignals();
void spinUntilStopped(double period_s, bool always_stop, const std::function<void()>& stop);

}  // namespace cartpole_qlearning
