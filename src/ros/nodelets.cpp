// The nodes as nodelets: the same classes as the executables, in one manager, so states
// and commands pass as pointers instead of through sockets.
//
// The lockstep topics (the sim's commands, the controller's states) of every cartpole nodelet
// in a manager queue on one callback queue served by one thread of their own. A step is then
// two callbacks in a row on that thread: a published message waits in the queue until the
// callback that published it returns, and no thread is ever woken for it. Through the
// manager's own queues each message would cross threads (its dispatcher, then a worker), which
// costs about ten times more than the step itself (bench/run_benchmarks.sh). Timers and the
// sim's services stay on the manager's threads (the controller serves save, load and live tuning
// on a thread of its own); the node classes lock their state for that.
#include "cartpole_qlearning/ros/cartpole_sim.h"
#include "cartpole_qlearning/ros/command_watchdog.h"
#include "cartpole_qlearning/ros/qlearning_controller.h"
#include "start_up.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/callback_queue.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace cartpole_qlearning
{
namespace
{
class LockstepThread
{
public:
  // The manager's one instance, made by its first user and ended with its last.
  static std::shared_ptr<LockstepThread> acquire()
  {
    static std::mutex mutex;
    static std::weak_ptr<LockstepThread> instance;
    const std::lock_guard<std::mutex> lock(mutex);
    std::shared_ptr<LockstepThread> thread = instance.lock();
    if (!thread)
    {
      thread = std::make_shared<LockstepThread>();
      instance = thread;
    }
    return thread;
  }

  LockstepThread() : thread_([this] { serve(); }) {}
  ~LockstepThread()
  {
    stopping_ = true;
    thread_.join();
  }
  LockstepThread(const LockstepThread&) = delete;
  LockstepThread& operator=(const LockstepThread&) = delete;

  ros::CallbackQueue* queue()
  {
    return &queue_;
  }

private:
  void serve()
  {
    while (!stopping_ && ros::ok())
      queue_.callAvailable(ros::WallDuration(0.1));
  }

  ros::CallbackQueue queue_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

// What differs between the two nodes as nodelets: how each is made and what it does when unloaded.
template <class Node>
struct NodeletTraits;

template <>
struct NodeletTraits<CartPoleSimNode>
{
  static constexpr const char* kType = "cartpole_sim";
  static std::unique_ptr<CartPoleSimNode> make(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                               ros::CallbackQueue* queue)
  {
    return std::make_unique<CartPoleSimNode>(nh, pnh, queue);
  }
  static void unload(CartPoleSimNode&) {}
};

template <>
struct NodeletTraits<QLearningControllerNode>
{
  static constexpr const char* kType = "qlearning_controller";
  // When training ends the controller saves, reports and stops acting; the manager and the other
  // nodelets keep running unless ~shutdown_when_finished asks to end the manager (train.launch
  // nodelet:=true, where the manager is the run's own).
  static std::unique_ptr<QLearningControllerNode> make(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                                       ros::CallbackQueue* queue)
  {
    return std::make_unique<QLearningControllerNode>(
        nh, pnh, [] { ros::requestShutdown(); }, false, queue);
  }
  // Unloaded (or its manager stopping): zero effort first, as the executable does on Ctrl-C, since
  // a robot's forward controller holds the last command forever. While ROS runs, a moment for the
  // zero to leave on the connections to other processes, which the publishers' end closes.
  static void unload(QLearningControllerNode& node)
  {
    if (ros::ok())
    {
      node.stop();
      ros::WallDuration(0.2).sleep();
    }
  }
};

template <>
struct NodeletTraits<CommandWatchdogNode>
{
  static constexpr const char* kType = "command_watchdog";
  // Its commands on the manager's own queues: it is no part of a lockstep step.
  static std::unique_ptr<CommandWatchdogNode> make(const ros::NodeHandle& nh, const ros::NodeHandle& pnh,
                                                   ros::CallbackQueue*)
  {
    return std::make_unique<CommandWatchdogNode>(nh, pnh);
  }
  // Unloaded (or its manager stopping): the robot gets 0 when it may be pushed, as the executable does.
  static void unload(CommandWatchdogNode& node)
  {
    if (ros::ok())
    {
      node.stop();
      ros::WallDuration(0.2).sleep();
    }
  }
};

// A node class as a nodelet: the same class the executable runs, its lockstep topics on the
// manager's lockstep thread.
template <class Node>
class NodeNodelet : public nodelet::Nodelet
{
public:
  ~NodeNodelet() override
  {
    if (node_)
      NodeletTraits<Node>::unload(*node_);
    node_.reset();  // before the thread that serves its callbacks
  }

private:
  void onInit() override
  {
    // Its loader would respawn into the same error: startNode ends the launch that started the
    // manager instead (as for the executables), and the manager is told it failed.
    std::string reason;
    if (!startNode(
            NodeletTraits<Node>::kType, getName(),
            [&] {
              lockstep_ = LockstepThread::acquire();
              node_ = NodeletTraits<Node>::make(getNodeHandle(), getPrivateNodeHandle(), lockstep_->queue());
            },
            &reason))
      throw std::runtime_error(reason);
  }

  std::shared_ptr<LockstepThread> lockstep_;
  std::unique_ptr<Node> node_;
};

}  // namespace

using CartPoleSimNodelet = NodeNodelet<CartPoleSimNode>;
using QLearningControllerNodelet = NodeNodelet<QLearningControllerNode>;
using CommandWatchdogNodelet = NodeNodelet<CommandWatchdogNode>;

}  // namespace cartpole_qlearning

PLUGINLIB_EXPORT_CLASS(cartpole_qlearning::CartPoleSimNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(cartpole_qlearning::QLearningControllerNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(cartpole_qlearning::CommandWatchdogNodelet, nodelet::Nodelet)
