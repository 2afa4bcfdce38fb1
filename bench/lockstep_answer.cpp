// lockstep_answer: drives cartpole_sim in lockstep as fast as it goes. Answers every state on
// joint_states with a constant effort on joint_command, stamped with the state's stamp as the
// controller answers (no decision: the cheapest controller), and counts states per wall second
// over a fixed duration. The sim needs no reset: the physics just go on, and stay finite (a
// constant push for a million steps is checked to). Prints one line
// "states=N repeats=R wall_s=T rate=R". repeats are states received again with the stamp of the
// one before, which the sim sends when it has not stepped on an answer within its
// lockstep_timeout (the answer was lost, or came too late); they should be 0. A sim that never
// steps on our answers (one that drops them: a stamp it does not await) would only repeat its
// state: that is an error (exit 1 after ~start_timeout), not a count of repeats.
//
// usage: lockstep_answer __ns:=cartpole [_duration:=3.0] [_warmup:=0.5] [_effort:=10.0] [_start_timeout:=5.0]
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <chrono>
#include <cstdint>
#include <cstdio>

namespace
{
using Clock = std::chrono::steady_clock;

class LockstepAnswer
{
public:
  LockstepAnswer(ros::NodeHandle& nh, double warmup, double duration, double effort, double start_timeout)
    : warmup_(warmup), duration_(duration)
  {
    command_.name = {"cart_joint"};
    command_.effort = {effort};
    command_pub_ = nh.advertise<sensor_msgs::JointState>("joint_command", 10);
    state_sub_ = nh.subscribe("joint_states", 10, &LockstepAnswer::onState, this, ros::TransportHints().tcpNoDelay());
    start_timer_ = nh.createSteadyTimer(ros::WallDuration(start_timeout), &LockstepAnswer::onStartTimeout, this, true);
  }

  bool failed() const
  {
    return failed_;
  }

private:
  void onStartTimeout(const ros::SteadyTimerEvent&)
  {
    if (started_)
      return;
    ROS_ERROR(
        "lockstep_answer: the sim has not stepped on an answer of ours (%s on %s): no lockstep sim there, or "
        "it drops our joint_command",
        have_first_stamp_ ? "only one state, repeated" : "no state", state_sub_.getTopic().c_str());
    failed_ = true;
    ros::shutdown();
  }

  void answer(const sensor_msgs::JointState& state)
  {
    // A repeat is answered again, as the controller does: its first answer may be the one that
    // was lost, and a second one that is not is dropped by the sim (at most one step per stamp).
    command_.header.stamp = state.header.stamp;
    command_pub_.publish(command_);
  }

  void onState(const sensor_msgs::JointStateConstPtr& msg)
  {
    const Clock::time_point now = Clock::now();
    if (!started_)
    {
      // Warm up from the first state that follows an answer of ours: until then an answer can be
      // lost while the connections come up, and the sim sends the state again only after its
      // lockstep_timeout. The first state is the one the last client left unanswered, sent
      // again by the sim when this one subscribed.
      if (!have_first_stamp_)
      {
        first_stamp_ = msg->header.stamp;
        have_first_stamp_ = true;
      }
      else if (msg->header.stamp != first_stamp_)
      {
        started_ = true;
        warmup_start_ = now;
      }
    }
    if (!started_)
    {
      answer(*msg);
      return;
    }
    if (!counting_ && now - warmup_start_ >= std::chrono::duration<double>(warmup_))
    {
      counting_ = true;
      start_ = now;
    }
    if (counting_)
    {
      ++count_;
      if (have_stamp_ && msg->header.stamp == last_stamp_)
        ++repeats_;
      const double elapsed = std::chrono::duration<double>(now - start_).count();
      if (elapsed >= duration_)
      {
        std::printf("states=%llu repeats=%llu wall_s=%.3f rate=%.1f\n", static_cast<unsigned long long>(count_),
                    static_cast<unsigned long long>(repeats_), elapsed, count_ / elapsed);
        std::fflush(stdout);
        ros::shutdown();
        return;
      }
    }
    last_stamp_ = msg->header.stamp;
    have_stamp_ = true;
    answer(*msg);
  }

  double warmup_;
  double duration_;
  sensor_msgs::JointState command_;
  ros::Publisher command_pub_;
  ros::Subscriber state_sub_;
  ros::SteadyTimer start_timer_;
  bool failed_ = false;
  bool have_first_stamp_ = false;
  ros::Time first_stamp_;
  bool started_ = false;
  bool counting_ = false;
  bool have_stamp_ = false;
  ros::Time last_stamp_;
  Clock::time_point warmup_start_;
  Clock::time_point start_;
  std::uint64_t count_ = 0;
  std::uint64_t repeats_ = 0;
};
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "lockstep_answer");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  double duration = 3.0;
  double warmup = 0.5;
  double effort = 10.0;
  double start_timeout = 5.0;
  pnh.param("duration", duration, duration);
  pnh.param("warmup", warmup, warmup);
  pnh.param("effort", effort, effort);
  pnh.param("start_timeout", start_timeout, start_timeout);
  if (!(duration > 0.0) || !(warmup >= 0.0) || !(start_timeout > 0.0))
  {
    ROS_ERROR("lockstep_answer: ~duration and ~start_timeout must be > 0 and ~warmup >= 0 (got %g, %g, %g)", duration,
              start_timeout, warmup);
    return 1;
  }
  LockstepAnswer answer(nh, warmup, duration, effort, start_timeout);
  ros::spin();
  return answer.failed() ? 1 : 0;
}
