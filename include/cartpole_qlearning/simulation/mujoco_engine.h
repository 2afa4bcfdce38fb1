// A MuJoCo model (MJCF) as the cart-pole's physics. Built into its own library
// (cartpole_qlearning_mujoco) when MuJoCo is found; physics_engines.h makes one from a config, so
// nothing else links MuJoCo. The model names the cart's slide joint, the pole's hinge joint and a
// motor on the slide (EngineParams); the state is their qpos and qvel, theta's sign chosen so
// that positive leans the pole toward +x (the slide's direction), whatever the hinge's axis.
#pragma once

#include "cartpole_qlearning/simulation/physics_engine.h"

#include <memory>
#include <string>
#include <vector>

// MuJoCo's types, declared here so that this header does not need MuJoCo's.
typedef struct mjModel_ mjModel;
typedef struct mjData_ mjData;

namespace cartpole_qlearning
{
class MujocoEngine : public PhysicsEngine
{
public:
  // Loads params.model and checks it: a model that fails to load, a joint or actuator that is
  // missing or of the wrong kind, a tau that is not a whole number of the model's timesteps
  // throw EngineError naming the key (physics/model, cart_joint, pole_joint, actuator, tau) and
  // the model.
  MujocoEngine(const EngineParams& params, double tau);
  MujocoEngine(const MujocoEngine& other);
  MujocoEngine& operator=(const MujocoEngine&) = delete;
  ~MujocoEngine() override;

  std::unique_ptr<PhysicsEngine> clone() const override
  {
    return std::make_unique<MujocoEngine>(*this);
  }
  double tau() const override
  {
    return tau_;
  }
  double forceLimit() const override;
  // Scales the cart's and the pole's bodies (mass and inertia) and the motor's gain.
  void setFactors(const EpisodeFactors& factors) override;
  // mj_resetData, then the two joints' qpos and qvel from the state, then mj_forward.
  void setState(const CartPoleState& state) override;
  // ctrl = command / gear, clamped to the actuator's ctrlrange (a clamp is counted); the push is
  // a force on the cart's body along the slide; then frameSkip() mj_steps.
  double step(double command, double push) override;
  const CartPoleState& state() const override
  {
    return state_;
  }
  std::uint64_t clamps() const override
  {
    return clamps_;
  }

  // The bodies cart_joint and pole_joint move.
  std::string cartBody() const override;
  std::string poleBody() const override;
  // mj_steps per tau (tau / the model's timestep).
  int frameSkip() const
  {
    return frame_skip_;
  }
  // The force one unit of ctrl gives [N] (the actuator's gear times its gain).
  double gear() const
  {
    return gear_;
  }
  // +1 or -1: theta = thetaSign() * the hinge's qpos.
  double thetaSign() const
  {
    return theta_sign_;
  }
  // This episode's model and the simulation's data (for tests and tools; MuJoCo's headers read them).
  const mjModel& model() const
  {
    return *model_;
  }
  const mjData& data() const
  {
    return *data_;
  }
  const EngineParams& params() const
  {
    return params_;
  }

private:
  void readState();
  // mj_resetData's outcome without its cost (resetData in the .cpp).
  void resetData();

  EngineParams params_;
  double tau_;
  std::shared_ptr<const mjModel> loaded_;  // the model as loaded (shared by copies)
  mjModel* model_ = nullptr;               // this episode's: masses and gain scaled
  mjData* data_ = nullptr;
  int cart_qpos_ = 0, cart_dof_ = 0, pole_qpos_ = 0, pole_dof_ = 0;
  int cart_body_ = 0, pole_body_ = 0, actuator_ = 0;
  int frame_skip_ = 1;
  double gear_ = 1.0;
  double theta_sign_ = 1.0;
  double slide_axis_[3] = {1.0, 0.0, 0.0};  // in world coordinates, for pushes
  CartPoleState state_ = CartPoleState::Zero();
  double motor_factor_ = 1.0;
  std::uint64_t clamps_ = 0;
  // mjData's header (sizes, counters, time) as mj_resetData leaves it, restored at each start
  // (MuJoCo 2.2: see resetData).
  std::vector<unsigned char> reset_header_;
};

}  // namespace cartpole_qlearning
