// What a service is, found out the way `rosservice info` and `rosservice type` do.
// Hand-made because roscpp cannot tell: ros::service::exists and ServiceClient only say whether a
// call of the type we name is accepted, never which type the server has (only rospy's rosservice
// module sends a probe header), and "it serves std_srvs/Trigger, not Reset" is the message a user needs.
#pragma once

#include "cartpole_qlearning/protocol/reset_calls.h"

#include <chrono>
#include <string>

namespace cartpole_qlearning
{
// Asks the master which node serves `service` (lookupService): Missing when it knows none. Else
// connects to that server and sends a probe's connection header (probe=1, md5sum=*, so that the
// server accepts whatever the type), and reads the type and md5sum its header answers with:
// Served. Unknown when the master or the server cannot be asked, or does not answer within
// `timeout` (each of the connect, the write and the read). Blocks for as long: call it off the
// control path (ResetCaller's calling thread).
ServiceFound probeService(const std::string& service, const std::string& caller_id, std::chrono::milliseconds timeout);

}  // namespace cartpole_qlearning
