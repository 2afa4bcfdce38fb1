// One learner, three robots each as it comes (started by hung_reset.test). This node serves
// robot_1's reset service itself: the first call it gets never returns (a sim stuck in its
// callback, or a host gone with the connection half-open), later calls go on to robot_1's real
// sim. The learner must keep training robot_0 and robot_2 while that call hangs, give the call
// up after max(5 s, 2 x ~sim_timeout) with a warning, and take robot_1 back. A Ctrl-C while a
// call hangs still saves the table and ends the controller.
#include "cartpole_qlearning/EpisodeStats.h"
#include "cartpole_qlearning/Reset.h"

#include "ros_test_support.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>

#include <array>
#include <filesystem>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

#include <signal.h>

using cartpole_qlearning::EpisodeStats;
using cartpole_qlearning::EpisodeStatsConstPtr;
using cartpole_qlearning::Reset;
using cartpole_qlearning::test::pidOf;
using cartpole_qlearning::test::privateParam;
using cartpole_qlearning::test::processGone;
using cartpole_qlearning::test::spinUntil;
namespace fs = std::filesystem;

namespace
{
constexpr std::size_t kRobots = 3;
const char* const kHungService = "/hung_reset/robot_1/cartpole_sim/reset";
const char* const kRealService = "/hung_reset/robot_1/real_sim/reset";

// robot_1's reset service: the first call (and the next after hangNext()) blocks until
// release(), the others are forwarded.
class HangingReset
{
public:
  HangingReset() : spinner_(4, &queue_)
  {
    ros::NodeHandle nh;
    nh.setCallbackQueue(&queue_);
    server_ = nh.advertiseService(kHungService, &HangingReset::onReset, this);
    spinner_.start();
  }
  ~HangingReset()
  {
    release();
    spinner_.stop();
  }

  bool hanging() const
  {
    return hangs_ > 0;
  }
  int hangs() const
  {
    return hangs_;
  }
  void hangNext()
  {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      released_ = false;
    }
    hang_next_ = true;
  }
  void release()
  {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      released_ = true;
    }
    released_cv_.notify_all();
  }

private:
  bool onReset(Reset::Request& request, Reset::Response& response)
  {
    if (hang_next_.exchange(false))
    {
      ++hangs_;
      std::unique_lock<std::mutex> lock(mutex_);
      released_cv_.wait(lock, [this] { return released_; });
      return false;
    }
    Reset forwarded;
    forwarded.request = request;
    if (!ros::service::call(kRealService, forwarded))
      return false;
    response = forwarded.response;
    return true;
  }

  ros::CallbackQueue queue_;
  ros::AsyncSpinner spinner_;
  ros::ServiceServer server_;
  std::atomic<bool> hang_next_{true};
  std::atomic<int> hangs_{0};
  std::mutex mutex_;
  std::condition_variable released_cv_;
  bool released_ = false;
};

}  // namespace

TEST(HungReset, AHungResetHoldsUpOnlyItsRobotAndIsGivenUp)
{
  ros::NodeHandle nh;
  std::array<std::size_t, kRobots> episodes{};
  std::string given_up;
  bool answers_again = false;
  std::vector<ros::Subscriber> subs;
  for (std::size_t r = 0; r < kRobots; ++r)
    subs.push_back(nh.subscribe<EpisodeStats>("/hung_reset/robot_" + std::to_string(r) + "/episode_stats", 10000,
                                              boost::function<void(const EpisodeStatsConstPtr&)>(
                                                  [&episodes, r](const EpisodeStatsConstPtr&) { ++episodes[r]; })));
  ros::Subscriber log = nh.subscribe<rosgraph_msgs::Log>(
      "/rosout", 1000,
      boost::function<void(const rosgraph_msgs::LogConstPtr&)>([&](const rosgraph_msgs::LogConstPtr& m) {
        if (m->msg.find(std::string("reset call to ") + kHungService + " has not returned after") != std::string::npos)
          given_up = m->msg;
        if (m->msg.find(std::string(kHungService) + " answers again") != std::string::npos)
          answers_again = true;
      }));
  HangingReset hanging_reset;

  ASSERT_TRUE(spinUntil([&] { return hanging_reset.hanging(); }, 20.0))
      << "robot_1's reset was never called: " << episodes[0] << ", " << episodes[1] << ", " << episodes[2]
      << " episodes";
  // While robot_1's call hangs (it is given up only after 5 s), the other two go on.
  const auto at_hang = episodes;
  EXPECT_TRUE(spinUntil([&] { return episodes[0] >= at_hang[0] + 10 && episodes[2] >= at_hang[2] + 10; }, 4.0))
      << "robot_0 and robot_2 stopped while robot_1's reset hung: " << episodes[0] - at_hang[0] << ", "
      << episodes[2] - at_hang[2] << " episodes since";
  EXPECT_TRUE(given_up.empty()) << "given up too soon: " << given_up;

  ASSERT_TRUE(spinUntil([&] { return !given_up.empty(); }, 15.0)) << "the learner never gave the hung call up";
  EXPECT_NE(std::string::npos, given_up.find("after 5.0 s")) << given_up;
  const auto at_give_up = episodes;
  EXPECT_TRUE(spinUntil([&] { return answers_again && episodes[1] >= at_give_up[1] + 10; }, 10.0))
      << "robot_1 did not take part again: " << episodes[1] - at_give_up[1] << " episodes since the call was given up"
      << (answers_again ? "" : "; no 'answers again'");
  EXPECT_TRUE(spinUntil([&] { return episodes[0] > at_give_up[0] && episodes[2] > at_give_up[2]; }, 5.0))
      << "robot_0 and robot_2 stopped after robot_1 came back";

  // The given-up call returns at last (a failure): the learner must not mind.
  hanging_reset.release();
  const auto at_release = episodes;
  EXPECT_TRUE(spinUntil(
      [&] {
        return episodes[0] >= at_release[0] + 10 && episodes[1] >= at_release[1] + 10 &&
               episodes[2] >= at_release[2] + 10;
      },
      10.0))
      << "training did not go on once the given-up call returned";

  // Ctrl-C while robot_1's next call hangs: the controller saves its table (its only save: no
  // checkpoints in this launch) and ends, though the call would never return. (In this process
  // roscpp's own shutdown drops the hung connection too; a nodelet's unload has no such help,
  // and there only ResetCaller's giving up keeps the save from waiting.)
  hanging_reset.hangNext();
  ASSERT_TRUE(spinUntil([&] { return hanging_reset.hangs() == 2; }, 20.0)) << "robot_1's reset was not called again";
  const int controller = pidOf("/hung_reset/qlearning_controller");
  ASSERT_GT(controller, 0);
  ::kill(controller, SIGINT);
  const ros::WallTime interrupted = ros::WallTime::now();
  EXPECT_TRUE(spinUntil([&] { return processGone(controller); }, 15.0))
      << "the controller did not end on Ctrl-C while a reset call hung";
  std::cout << "the controller ended " << (ros::WallTime::now() - interrupted).toSec()
            << " s after Ctrl-C, with a reset call hanging\n";
  bool saved = false;
  std::error_code error;
  const fs::path runs = fs::path(privateParam("q_table_dir")) / "runs";
  for (const auto& run : fs::directory_iterator(runs, error))
    saved = saved || fs::exists(run.path() / "q_table.yaml");
  EXPECT_TRUE(saved) << "no table saved on shutdown under " << runs;
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "hung_reset_test");
  ros::NodeHandle nh;
  const int result = RUN_ALL_TESTS();
  fs::remove_all(privateParam("q_table_dir"));
  return result;
}
