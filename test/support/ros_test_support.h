// Helpers the rostest test nodes share.
#pragma once

#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <gtest/gtest.h>

#include "test_support.h"

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
namespace test
{
// A string parameter of this test node's own (the .test file sets it), "" when absent.
inline std::string privateParam(const std::string& name)
{
  std::string value;
  ros::param::get("~" + name, value);
  return value;
}

// Spins the global callback queue until done() holds or the wall-clock timeout passes (wall
// clock: in lockstep, ROS time is the sim's and may stand still).
inline bool spinUntil(const std::function<bool()>& done, double timeout_s)
{
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    if (done())
      return true;
    ros::WallDuration(0.001).sleep();
  }
  ros::spinOnce();
  return done();
}

// Spins until done() holds, for as long as progress() (a count: episodes seen) keeps growing:
// false once it has stood still for stall_s (three times that before it first moves: the nodes
// start meanwhile) or cap_s has passed in all (wall clock both). For a training over the graph,
// whose pace is the machine's: lockstep waits on the scheduler twice a step, and a machine
// running three tests beside a compiler slowed one that takes 25-40 s under ASan past 200 s
// (CI on c5a9f2c: 221 of its 259 episodes), nothing being wrong; a stall is.
inline bool spinWhileProgressing(const std::function<bool()>& done, const std::function<std::size_t()>& progress,
                                 double stall_s, double cap_s)
{
  const ros::WallTime cap = ros::WallTime::now() + ros::WallDuration(cap_s);
  std::size_t seen = progress();
  ros::WallTime moved = ros::WallTime::now();
  bool moved_once = false;
  while (ros::ok() && ros::WallTime::now() < cap &&
         (ros::WallTime::now() - moved).toSec() < (moved_once ? stall_s : 3.0 * stall_s))
  {
    ros::spinOnce();
    if (done())
      return true;
    if (progress() != seen)
    {
      seen = progress();
      moved = ros::WallTime::now();
      moved_once = true;
    }
    ros::WallDuration(0.001).sleep();
  }
  ros::spinOnce();
  return done();
}

// The URI the master has for a node ("" when it has none).
inline std::string uriOf(const std::string& node)
{
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, payload, false) ||
      payload.getType() != XmlRpc::XmlRpcValue::TypeString)
    return "";
  return static_cast<std::string>(payload);
}

// Calls a node's slave API (XML-RPC) with the caller id as the only argument, as rosnode does;
// its raw answer (normally [1, message, value]), or a value of no type.
inline XmlRpc::XmlRpcValue callNodeRaw(const std::string& node, const char* method)
{
  std::string host;
  std::uint32_t port = 0;
  if (!ros::network::splitURI(uriOf(node), host, port))
    return {};
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue args, result;
  args[0] = ros::this_node::getName();
  const bool ok = client.execute(method, args, result);
  client.close();
  return ok ? result : XmlRpc::XmlRpcValue();
}

// The value of a successful answer [1, message, value], or a value of no type.
inline XmlRpc::XmlRpcValue callNode(const std::string& node, const char* method)
{
  XmlRpc::XmlRpcValue result = callNodeRaw(node, method);
  if (result.getType() != XmlRpc::XmlRpcValue::TypeArray || result.size() != 3 ||
      result[0].getType() != XmlRpc::XmlRpcValue::TypeInt || static_cast<int>(result[0]) != 1)
    return {};
  return result[2];
}

// The pid a node reports (getPid), or -1 when it does not answer.
inline int pidOf(const std::string& node)
{
  XmlRpc::XmlRpcValue pid = callNode(node, "getPid");
  return pid.getType() == XmlRpc::XmlRpcValue::TypeInt ? static_cast<int>(pid) : -1;
}

// The final table of the one run folder under ROS_HOME `home`'s default namespace (a run that does not
// solve writes no default table, only its run folder's); "" and a failure when there is not one.
inline std::string runTable(const std::string& home)
{
  std::vector<std::filesystem::path> runs;
  for (const auto& entry : std::filesystem::directory_iterator(home + "/cartpole_qlearning/cartpole/runs"))
    runs.push_back(entry.path());
  EXPECT_EQ(1u, runs.size()) << home;
  return runs.empty() ? "" : fileText((runs.front() / "q_table.yaml").string());
}

}  // namespace test
}  // namespace cartpole_qlearning
