// lockstep_answer: drives cartpole_sim in lockstep as fast as it goes. Answers every state on
// joint_states with a constant effort on cart_effort (no decision: the cheapest controller) and
// counts states per wall second over a fixed duration. The sim needs no reset: the physics just
// go on, and stay finite (a constant push for a million steps is checked to). Prints one line
// "states=N repeats=R wall_s=T rate=R"; repeats are states published again with the same stamp
// (an answer that did not arrive within the sim's lockstep_timeout), which should be 0.
//
// usage: lockstep_answer __ns:=cartpole [_duration:=3.0] [_warmup:=0.5] [_effort:=10.0]
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

#include <chrono>
#include <cstdint>
#include <cstdio>

namespace
{
using Clock = std::chrono::steady_clock;

class LockstepAnswer
{
public:
  LockstepAnswer(ros::NodeHandle& nh, double warmup, double duration, double effort)
    : warmup_(warmup), duration_(duration)
  {
    answer_.data = effort;
    effort_pub_ = nh.advertise<std_msgs::Float64>("cart_effort", 10);
    state_sub_ = nh.subscribe("joint_states", 10, &LockstepAnswer::onState, this, ros::TransportHints().tcpNoDelay());
  }

private:
  void onState(const sensor_msgs::JointStateConstPtr& msg)
  {
    const Clock::time_point now = Clock::now();
    if (!started_)
    {
      // Warm up from the first state that follows an answer of ours: until then an answer can be
      // lost while the connections come up, and the sim sends the state again only after its
      // lockstep_timeout.
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
      effort_pub_.publish(answer_);
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
    effort_pub_.publish(answer_);
  }

  double warmup_;
  double duration_;
  std_msgs::Float64 answer_;
  ros::Publisher effort_pub_;
  ros::Subscriber state_sub_;
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
  pnh.param("duration", duration, duration);
  pnh.param("warmup", warmup, warmup);
  pnh.param("effort", effort, effort);
  if (!(duration > 0.0) || !(warmup >= 0.0))
  {
    ROS_ERROR("lockstep_answer: ~duration must be > 0 and ~warmup >= 0 (got %g, %g)", duration, warmup);
    return 1;
  }
  LockstepAnswer answer(nh, warmup, duration, effort);
  ros::spin();
  return 0;
}
