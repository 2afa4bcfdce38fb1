// intraprocess_pair: the reference for the nodelet loop. A ping and a pong in one process pass
// messages shaped like the lockstep loop's (a 2-joint sensor_msgs/JointState state, answered by
// a 1-joint JointState command stamped with the state's stamp) as shared pointers, which roscpp
// hands from publisher to subscriber without serialising. Counts round trips over a fixed wall
// duration and prints one line "round_trips=N wall_s=T rate=R".
//   _threads:=1  both subscriptions on one callback queue, served by one thread: a message
//                waits in the queue until the callback that published it returns
//   _threads:=2  each on its own queue and thread: every message wakes the other thread
//
// usage: intraprocess_pair [_threads:=1] [_duration:=3.0] [_warmup:=0.5]
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <thread>

namespace
{
using Clock = std::chrono::steady_clock;

class Pair
{
public:
  Pair(ros::CallbackQueue* ping_queue, ros::CallbackQueue* pong_queue, double warmup, double duration)
    : ping_nh_("intraprocess_pair"), pong_nh_("intraprocess_pair"), warmup_(warmup), duration_(duration)
  {
    ping_nh_.setCallbackQueue(ping_queue);
    pong_nh_.setCallbackQueue(pong_queue);
    state_pub_ = ping_nh_.advertise<sensor_msgs::JointState>("state", 10);
    command_pub_ = pong_nh_.advertise<sensor_msgs::JointState>("command", 10);
    state_sub_ = pong_nh_.subscribe("state", 10, &Pair::onState, this);
    command_sub_ = ping_nh_.subscribe("command", 10, &Pair::onCommand, this);
  }

  // Publishes the first state once both subscriptions are connected.
  void start()
  {
    while (ros::ok() && (state_pub_.getNumSubscribers() == 0 || command_pub_.getNumSubscribers() == 0))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    warmup_start_ = Clock::now();
    publishState(1);
  }

  bool done() const
  {
    return done_;
  }

private:
  void publishState(std::uint64_t n)
  {
    auto state = boost::make_shared<sensor_msgs::JointState>();
    state->header.stamp.fromNSec(n * 20000000ULL);
    state->name = {"cart_joint", "pole_joint"};
    state->position = {0.01, 0.02};
    state->velocity = {-0.01, 0.03};
    state->effort = {10.0, 0.0};
    state_pub_.publish(state);
  }

  void onState(const sensor_msgs::JointStateConstPtr& state)
  {
    auto command = boost::make_shared<sensor_msgs::JointState>();
    command->header.stamp = state->header.stamp;
    command->name = {"cart_joint"};
    command->effort = {-state->effort[0]};
    command_pub_.publish(command);
  }

  void onCommand(const sensor_msgs::JointStateConstPtr& command)
  {
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
        done_ = true;
        return;
      }
    }
    publishState(command->header.stamp.toNSec() / 20000000ULL + 1);
  }

  ros::NodeHandle ping_nh_;
  ros::NodeHandle pong_nh_;
  double warmup_;
  double duration_;
  ros::Publisher state_pub_;
  ros::Publisher command_pub_;
  ros::Subscriber state_sub_;
  ros::Subscriber command_sub_;
  std::atomic<bool> done_{false};
  bool counting_ = false;
  Clock::time_point warmup_start_;
  Clock::time_point start_;
  std::uint64_t count_ = 0;
};

void serve(ros::CallbackQueue& queue, const Pair& pair)
{
  while (ros::ok() && !pair.done())
    queue.callAvailable(ros::WallDuration(0.1));
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "intraprocess_pair", ros::init_options::AnonymousName);
  ros::NodeHandle pnh("~");
  int threads = 1;
  double duration = 3.0;
  double warmup = 0.5;
  pnh.param("threads", threads, threads);
  pnh.param("duration", duration, duration);
  pnh.param("warmup", warmup, warmup);
  if ((threads != 1 && threads != 2) || !(duration > 0.0) || !(warmup >= 0.0))
  {
    ROS_ERROR("intraprocess_pair: ~threads must be 1 or 2, ~duration > 0, ~warmup >= 0 (got %d, %g, %g)", threads,
              duration, warmup);
    return 1;
  }
  ros::CallbackQueue ping_queue;
  ros::CallbackQueue pong_queue;
  Pair pair(&ping_queue, threads == 1 ? &ping_queue : &pong_queue, warmup, duration);
  std::thread ping_thread(serve, std::ref(ping_queue), std::cref(pair));
  std::thread pong_thread;
  if (threads == 2)
    pong_thread = std::thread(serve, std::ref(pong_queue), std::cref(pair));
  pair.start();
  ping_thread.join();
  if (pong_thread.joinable())
    pong_thread.join();
  return 0;
}
