// Both nodes as nodelets on one thread: episodes keep ending, so every reset call returned.
#include "cartpole_qlearning/EpisodeStats.h"

#include <gtest/gtest.h>
#include <ros/ros.h>

TEST(Nodelets, TrainingRunsEpisodeAfterEpisodeOnOneThread)
{
  ros::NodeHandle nh;
  std::uint32_t last_episode = 0;
  std::uint32_t received = 0;
  ros::Subscriber sub = nh.subscribe<cartpole_qlearning::EpisodeStats>(
      "/cartpole/episode_stats", 100,
      boost::function<void(const cartpole_qlearning::EpisodeStatsConstPtr&)>(
          [&](const cartpole_qlearning::EpisodeStatsConstPtr& m) {
            last_episode = m->episode;
            ++received;
          }));
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(60.0);
  while (ros::ok() && last_episode < 30 && ros::WallTime::now() < deadline)
  {
    ros::spinOnce();
    ros::WallDuration(0.01).sleep();
  }
  EXPECT_GE(last_episode, 30u) << "training stalled: " << received << " episode_stats received";
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "nodelets_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
