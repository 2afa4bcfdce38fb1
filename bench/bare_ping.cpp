// bare_ping: the reference for the lockstep rate. Exchanges the lockstep loop's messages between
// two processes over TCPROS and nothing else: publishes a sensor_msgs/JointState shaped like
// cartpole_sim's state (2 joints, 2 positions, 2 velocities, 2 efforts), waits for the command
// that answers it (a 1-joint JointState stamped with the state's stamp, as the controller's
// joint_command), publishes the next one, and counts round trips over a fixed wall duration.
// Prints one line "round_trips=N wall_s=T rate=R". Answered by bare_pong. Every state has a
// stamp of its own and only the command carrying the latest one moves on, so exactly one state
// is ever in flight.
//
// usage: bare_ping [_duration:=3.0] [_warmup:=0.5]   (topics ping_state, ping_command)
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <chrono>
#include <cstdint>
#include <cstdio>

namespace
{
using Clock = std::chrono::steady_clock;

class BarePing
{
public:
  BarePing(ros::NodeHandle& nh, double warmup, double duration) : warmup_(warmup), duration_(duration)
  {
    state_.name = {"cart_joint", "pole_joint"};
    state_.position = {0.01, 0.02};
    state_.velocity = {-0.01, 0.03};
    state_.effort = {10.0, 0.0};
    state_pub_ = nh.advertise<sensor_msgs::JointState>("ping_state", 10);
    command_sub_ = nh.subscribe("ping_command", 10, &BarePing::onCommand, this, ros::TransportHints().tcpNoDelay());
    // Until the first answer the connections may not be up yet: send again now and then. Wall
    // timer, so that /use_sim_time cannot stall it.
    retry_ = nh.createSteadyTimer(ros::WallDuration(0.1), &BarePing::onRetry, this);
  }

private:
  void publish()
  {
    ++state_.header.seq;
    state_.header.stamp.fromNSec(state_.header.seq * 20000000ULL);  // one 20 ms tick each, as the sim's
    state_pub_.publish(state_);
  }

  void onRetry(const ros::SteadyTimerEvent&)
  {
    if (!answered_)
      publish();
  }

  void onCommand(const sensor_msgs::JointStateConstPtr& msg)
  {
    if (msg->header.stamp != state_.header.stamp || msg->effort.empty())
      return;  // answers a retry sent before the connections were up: the latest one counts
    if (!answered_)
    {
      answered_ = true;
      retry_.stop();
      warmup_start_ = Clock::now();
    }
    const Clock::time_point now = Clock::now();
    if (!counting_ && now - warmup_start_ >= std::chrono::duration<double>(warmup_))
    {
      counting_ = true;
      start_ = now;
      count_ = 0;
    }
    if (counting_)
    {
      ++count_;
      const double elapsed = std::chrono::duration<double>(now - start_).count();
      if (elapsed >= duration_)
      {
        std::printf("round_trips=%llu wall_s=%.3f rate=%.1f\n", static_cast<unsigned long long>(count_), elapsed,
                    count_ / elapsed);
        std::fflush(stdout);
        ros::shutdown();
        return;
      }
    }
    state_.effort[0] = msg->effort[0];  // the applied effort, as the sim reports it
    publish();
  }

  double warmup_;
  double duration_;
  sensor_msgs::JointState state_;
  ros::Publisher state_pub_;
  ros::Subscriber command_sub_;
  ros::SteadyTimer retry_;
  bool answered_ = false;
  bool counting_ = false;
  Clock::time_point warmup_start_;
  Clock::time_point start_;
  std::uint64_t count_ = 0;
};
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "bare_ping");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  double duration = 3.0;
  double warmup = 0.5;
  pnh.param("duration", duration, duration);
  pnh.param("warmup", warmup, warmup);
  if (!(duration > 0.0) || !(warmup >= 0.0))
  {
    ROS_ERROR("bare_ping: ~duration must be > 0 and ~warmup >= 0 (got %g, %g)", duration, warmup);
    return 1;
  }
  BarePing ping(nh, warmup, duration);
  ros::spin();
  return 0;
}
