// The two nodes as nodelets: the same classes as the executables, in one manager, so states
// and commands pass as pointers instead of through sockets.
#include "cartpole_qlearning/cartpole_sim_node.h"
#include "cartpole_qlearning/qlearning_controller_node.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace cartpole_qlearning
{
class CartPoleSimNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    try
    {
      node_ = std::make_unique<CartPoleSimNode>(getNodeHandle(), getPrivateNodeHandle());
    }
    catch (const std::exception& e)
    {
      NODELET_FATAL("cartpole_sim: %s", e.what());
      throw;
    }
  }

  std::unique_ptr<CartPoleSimNode> node_;
};

class QLearningControllerNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    try
    {
      // A nodelet cannot end its manager: when training ends the controller saves, reports
      // and stops acting; the manager and the other nodelets keep running.
      node_ = std::make_unique<QLearningControllerNode>(getNodeHandle(), getPrivateNodeHandle(), nullptr);
    }
    catch (const std::exception& e)
    {
      NODELET_FATAL("qlearning_controller: %s", e.what());
      throw;
    }
  }

  std::unique_ptr<QLearningControllerNode> node_;
};

}  // namespace cartpole_qlearning

PLUGINLIB_EXPORT_CLASS(cartpole_qlearning::CartPoleSimNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(cartpole_qlearning::QLearningControllerNodelet, nodelet::Nodelet)
