#include "control_reporter.h"

#include "cartpole_qlearning/ControlStats.h"
#include "cartpole_qlearning/ros/conversions.h"

#include <utility>

namespace cartpole_qlearning
{
ControlReporter::ControlReporter(ros::NodeHandle& nh, const std::vector<std::string>& robots, double tau,
                                 double max_gap, double max_effort, double report_every, TaskKind task,
                                 double rail_limit, std::function<void(const LogLines&)> say)
  : robots_(robots), publisher_(nh.advertise<ControlStats>("control_stats", 100)), say_(std::move(say))
{
  for (const std::string& robot : robots_)
    meters_.emplace_back(robot, tau, max_gap, max_effort, report_every, task, rail_limit);
}

void ControlReporter::onReaction(std::size_t robot, const Reaction& reaction, bool fell, const CartPoleState& state)
{
  ControlMeter& meter = meters_.at(robot);
  const LogLines said = meter.onReaction(reaction, fell, state);
  if (said.empty())
    return;
  say_(said);
  publisher_.publish(controlStats(meter.stats(), robots_[robot], ros::Time().fromNSec(reaction.stamp)));
}

LogLines ControlReporter::summaries() const
{
  LogLines lines;
  for (const ControlMeter& meter : meters_)
    lines.push_back(meter.summary());
  return lines;
}

}  // namespace cartpole_qlearning
