// ~mode control's reports on the graph: a ControlMeter per robot (the core's), its lines said
// through the node's log and its figures published on control_stats in the learner's namespace.
#pragma once

#include "cartpole_qlearning/application/control_meter.h"
#include "cartpole_qlearning/common/log_line.h"

#include <ros/ros.h>

#include <functional>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
class ControlReporter
{
public:
  // robots: their namespaces ("" the learner's own); tau, max_gap, max_effort, report_every: as
  // ControlMeter takes them; say: the node's log.
  ControlReporter(ros::NodeHandle& nh, const std::vector<std::string>& robots, double tau, double max_gap,
                  double max_effort, double report_every, TaskKind task, double rail_limit,
                  std::function<void(const LogLines&)> say);

  // A state of `robot` as the protocol reacted to it (fell: the episode it ended ended on the
  // task's thresholds): the fall, the swing-up or the report said and published when due.
  void onReaction(std::size_t robot, const Reaction& reaction, bool fell, const CartPoleState& state);
  // The last lines, one per robot (the node stopping).
  LogLines summaries() const;

private:
  std::vector<std::string> robots_;
  std::vector<ControlMeter> meters_;
  ros::Publisher publisher_;
  std::function<void(const LogLines&)> say_;
};

}  // namespace cartpole_qlearning
