#include "cartpole_qlearning/simulation/mujoco_engine.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <functional>
#include <cstddef>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>

namespace cartpole_qlearning
{
namespace
{
const char* jointKind(int type)
{
  switch (type)
  {
    case mjJNT_FREE:
      return "free";
    case mjJNT_BALL:
      return "ball";
    case mjJNT_SLIDE:
      return "slide";
    case mjJNT_HINGE:
      return "hinge";
  }
  return "unknown";
}

// "slider (slide), hinge (hinge)"
std::string jointList(const mjModel* m)
{
  std::string list;
  for (int j = 0; j < m->njnt; ++j)
  {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    list +=
        (list.empty() ? "" : ", ") + std::string(name ? name : "(unnamed)") + " (" + jointKind(m->jnt_type[j]) + ")";
  }
  return list.empty() ? "none" : list;
}

std::string actuatorList(const mjModel* m)
{
  std::string list;
  for (int a = 0; a < m->nu; ++a)
  {
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
    list += (list.empty() ? "" : ", ") + std::string(name ? name : "(unnamed)");
  }
  return list.empty() ? "none" : list;
}

// MuJoCo's XML parser and compiler keep global state while they run: one model at a time
// (the robustness suite builds its cases' simulations on several threads).
std::mutex& loadMutex()
{
  static std::mutex mutex;
  return mutex;
}
// Refuses physics/KEY = VALUE, saying why (throws EngineError).
using Refusal = std::function<void(const std::string& key, const std::string& value, const std::string& why)>;

// The joint `key` names, of the type the cart-pole needs (a slide for the cart, a hinge for the pole).
int findJoint(const mjModel* m, const std::string& key, const std::string& name, int type, const std::string& needed,
              const Refusal& fail)
{
  const int joint = mj_name2id(m, mjOBJ_JOINT, name.c_str());
  if (joint < 0)
    fail(key, name, "no such joint (its joints: " + jointList(m) + ")");
  if (m->jnt_type[joint] != type)
    fail(key, name, std::string("a ") + jointKind(m->jnt_type[joint]) + " joint; " + needed);
  return joint;
}

// The force per unit of ctrl of the actuator, a motor on the cart's joint.
double motorGear(const mjModel* m, const EngineParams& params, int actuator, int cart, const Refusal& fail)
{
  if (actuator < 0)
    fail("actuator", params.actuator, "no such actuator (its actuators: " + actuatorList(m) + ")");
  if (m->actuator_trntype[actuator] != mjTRN_JOINT || m->actuator_trnid[2 * actuator] != cart)
    fail("actuator", params.actuator, "it does not act on physics/cart_joint '" + params.cart_joint + "'");
  if (m->actuator_dyntype[actuator] != mjDYN_NONE || m->actuator_gaintype[actuator] != mjGAIN_FIXED ||
      m->actuator_biastype[actuator] != mjBIAS_NONE)
    fail("actuator", params.actuator, "not a motor (a force of gear x ctrl: no dynamics, a fixed gain, no bias)");
  const double gear = m->actuator_gear[6 * actuator] * m->actuator_gainprm[mjNGAIN * actuator];
  if (!(std::isfinite(gear) && gear != 0.0))
    fail("actuator", params.actuator, "its gear times gain is 0: it gives no force");
  return gear;
}

// The model's timesteps in one step of tau (the frame skip): a whole number of them.
int wholeFrameSkip(const mjModel* m, double tau, const Refusal& fail)
{
  const double steps = tau / m->opt.timestep;
  const int frame_skip = static_cast<int>(std::llround(steps));
  if (!(std::isfinite(tau) && tau > 0.0 && frame_skip >= 1 && std::fabs(steps - frame_skip) <= 1e-9 * steps))
  {
    std::ostringstream why;
    why << "not a whole number of the model's timestep " << m->opt.timestep << " s (the frame skip)";
    std::ostringstream value;
    value << tau;
    fail("tau", value.str(), why.str());
  }
  return frame_skip;
}
}  // namespace

MujocoEngine::MujocoEngine(const EngineParams& params, double tau) : params_(params), tau_(tau)
{
  const std::string in_model = " in the model " + params.model;
  const Refusal fail = [&](const std::string& key, const std::string& value, const std::string& why) {
    throw EngineError("physics/" + key + " = '" + value + "'" + in_model + ": " + why);
  };
  if (params.model.empty())
    throw EngineError("physics/model is not set (physics/engine mujoco needs an MJCF file)");
  char error[1000] = "";
  mjModel* loaded = nullptr;
  {
    std::lock_guard<std::mutex> lock(loadMutex());
    loaded = mj_loadXML(params.model.c_str(), nullptr, error, sizeof error);
  }
  if (loaded == nullptr)
    throw EngineError("physics/model = '" + params.model + "' cannot be loaded: " + error);
  loaded_ = std::shared_ptr<const mjModel>(loaded, [](const mjModel* m) { mj_deleteModel(const_cast<mjModel*>(m)); });
  const mjModel* m = loaded;

  const int cart = findJoint(m, "cart_joint", params.cart_joint, mjJNT_SLIDE, "the cart's must be a slide joint", fail);
  const int pole = findJoint(m, "pole_joint", params.pole_joint, mjJNT_HINGE, "the pole's must be a hinge joint", fail);
  cart_body_ = m->jnt_bodyid[cart];
  pole_body_ = m->jnt_bodyid[pole];
  bool carried = false;
  for (int b = m->body_parentid[pole_body_]; b > 0 && !carried; b = m->body_parentid[b])
    carried = b == cart_body_;
  if (!carried)
    fail("pole_joint", params.pole_joint,
         "its body is not carried by the body of physics/cart_joint '" + params.cart_joint + "'");
  cart_qpos_ = m->jnt_qposadr[cart];
  cart_dof_ = m->jnt_dofadr[cart];
  pole_qpos_ = m->jnt_qposadr[pole];
  pole_dof_ = m->jnt_dofadr[pole];

  actuator_ = mj_name2id(m, mjOBJ_ACTUATOR, params.actuator.c_str());
  gear_ = motorGear(m, params, actuator_, cart, fail);
  frame_skip_ = wholeFrameSkip(m, tau, fail);

  model_ = mj_copyModel(nullptr, m);
  data_ = mj_makeData(model_);
  mj_resetData(model_, data_);
  const auto* header = reinterpret_cast<const unsigned char*>(data_);
  reset_header_.assign(header, header + offsetof(mjData, buffer));
  // Which way theta grows: a turn about the hinge's axis moves the pole's centre of mass by
  // axis x (centre - anchor); positive theta leans it toward the slide's +x.
  mj_forward(model_, data_);
  double lever[3];
  for (int k = 0; k < 3; ++k)
  {
    lever[k] = data_->xipos[3 * pole_body_ + k] - data_->xanchor[3 * pole + k];
    slide_axis_[k] = data_->xaxis[3 * cart + k];
  }
  const double* a = data_->xaxis + 3 * pole;
  const double turn[3] = {a[1] * lever[2] - a[2] * lever[1], a[2] * lever[0] - a[0] * lever[2],
                          a[0] * lever[1] - a[1] * lever[0]};
  const double along = turn[0] * slide_axis_[0] + turn[1] * slide_axis_[1] + turn[2] * slide_axis_[2];
  if (std::fabs(along) < 1e-9)
  {
    mj_deleteData(data_);
    mj_deleteModel(model_);
    fail("pole_joint", params.pole_joint, "turning it does not move the pole along the slide");
  }
  theta_sign_ = along > 0.0 ? 1.0 : -1.0;
  setState(CartPoleState::Zero());
}

MujocoEngine::MujocoEngine(const MujocoEngine& other)
  : params_(other.params_),
    tau_(other.tau_),
    loaded_(other.loaded_),
    model_(mj_copyModel(nullptr, other.model_)),
    data_(mj_copyData(nullptr, other.model_, other.data_)),
    cart_qpos_(other.cart_qpos_),
    cart_dof_(other.cart_dof_),
    pole_qpos_(other.pole_qpos_),
    pole_dof_(other.pole_dof_),
    cart_body_(other.cart_body_),
    pole_body_(other.pole_body_),
    actuator_(other.actuator_),
    frame_skip_(other.frame_skip_),
    gear_(other.gear_),
    theta_sign_(other.theta_sign_),
    state_(other.state_),
    motor_factor_(other.motor_factor_),
    clamps_(other.clamps_),
    reset_header_(other.reset_header_)
{
  for (int k = 0; k < 3; ++k)
    slide_axis_[k] = other.slide_axis_[k];
}

MujocoEngine::~MujocoEngine()
{
  mj_deleteData(data_);
  mj_deleteModel(model_);
}

std::string MujocoEngine::cartBody() const
{
  const char* name = mj_id2name(model_, mjOBJ_BODY, cart_body_);
  return name != nullptr ? name : "";
}

std::string MujocoEngine::poleBody() const
{
  const char* name = mj_id2name(model_, mjOBJ_BODY, pole_body_);
  return name != nullptr ? name : "";
}

double MujocoEngine::forceLimit() const
{
  if (!model_->actuator_ctrllimited[actuator_])
    return std::numeric_limits<double>::infinity();
  const double* range = model_->actuator_ctrlrange + 2 * actuator_;
  return std::fabs(gear_) * std::max(std::fabs(range[0]), std::fabs(range[1]));
}

void MujocoEngine::setFactors(const EpisodeFactors& factors)
{
  const mjModel* m = loaded_.get();
  for (const auto& [body, factor] :
       {std::pair<int, double>{cart_body_, factors.mass_cart}, {pole_body_, factors.mass_pole}})
  {
    model_->body_mass[body] = m->body_mass[body] * factor;
    for (int k = 0; k < 3; ++k)
      model_->body_inertia[3 * body + k] = m->body_inertia[3 * body + k] * factor;
  }
  model_->actuator_gainprm[mjNGAIN * actuator_] = m->actuator_gainprm[mjNGAIN * actuator_] * factors.motor;
  motor_factor_ = factors.motor;
}

void MujocoEngine::setState(const CartPoleState& state)
{
  const CartPoleState start = state;  // (it may be state_ itself)
  resetData();
  data_->qpos[cart_qpos_] = start[0];
  data_->qvel[cart_dof_] = start[1];
  data_->qpos[pole_qpos_] = theta_sign_ * start[2];
  data_->qvel[pole_dof_] = theta_sign_ * start[3];
  mj_forward(model_, data_);
  readState();
}

double MujocoEngine::step(double command, double push)
{
  double ctrl = command / gear_;
  if (model_->actuator_ctrllimited[actuator_])
  {
    const double* range = model_->actuator_ctrlrange + 2 * actuator_;
    const double clamped = std::min(std::max(ctrl, range[0]), range[1]);
    clamps_ += clamped != ctrl;
    ctrl = clamped;
  }
  data_->ctrl[actuator_] = ctrl;
  double* applied = data_->xfrc_applied + 6 * cart_body_;
  for (int k = 0; k < 3; ++k)
    applied[k] = push * slide_axis_[k];
  for (int i = 0; i < frame_skip_; ++i)
    mj_step(model_, data_);
  for (int k = 0; k < 3; ++k)
    applied[k] = 0.0;
  readState();
  return motor_factor_ * gear_ * ctrl + push;
}

void MujocoEngine::resetData()
{
#if mjVERSION_HEADER < 230
  // MuJoCo 2.2's mj_resetData zeroes all of mjData's memory: its buffer (3 MB for
  // mjcf/cartpole.xml's default sizes, the constraint arrays for njmax rows) and its stack (10 MB),
  // about 200 us and every cache line with it, at each episode's start. mj_forward computes
  // everything but the simulation's state and inputs from those, so only they are set as
  // mj_resetData sets them (MuJoCo's documentation, "Simulation state"): time and the counters
  // (the header as a reset leaves it), qpos0, zero velocities, activations, warm-start
  // accelerations, controls, applied forces and user data, mocap bodies where the model puts them.
  // Tables trained so are byte for byte those trained with mj_resetData (mujoco_cartpole.yaml
  // seeds 0-2, inverted_pendulum_v5.yaml seed 0, its slider limited).
  std::memcpy(static_cast<void*>(data_), reset_header_.data(), reset_header_.size());
  const mjModel* m = model_;
  mju_copy(data_->qpos, m->qpos0, m->nq);
  mju_zero(data_->qvel, m->nv);
  mju_zero(data_->act, m->na);
  mju_zero(data_->qacc_warmstart, m->nv);
  mju_zero(data_->ctrl, m->nu);
  mju_zero(data_->qfrc_applied, m->nv);
  mju_zero(data_->xfrc_applied, 6 * m->nbody);
  mju_zero(data_->userdata, m->nuserdata);
  for (int b = 0; b < m->nbody; ++b)
  {
    const int mocap = m->body_mocapid[b];
    if (mocap >= 0)
    {
      mju_copy3(data_->mocap_pos + 3 * mocap, m->body_pos + 3 * b);
      mju_copy4(data_->mocap_quat + 4 * mocap, m->body_quat + 4 * b);
    }
  }
#else
  mj_resetData(model_, data_);
#endif
}

void MujocoEngine::readState()
{
  state_ << data_->qpos[cart_qpos_], data_->qvel[cart_dof_], theta_sign_ * data_->qpos[pole_qpos_],
      theta_sign_ * data_->qvel[pole_dof_];
}

}  // namespace cartpole_qlearning

// What physics_engines.cpp looks up after loading this library on a config's first MuJoCo engine
// (dlopen): the engine made, or the EngineError its constructor throws.
extern "C" void cartpole_qlearning_make_mujoco_engine(const cartpole_qlearning::EngineParams& params, double tau,
                                                      std::unique_ptr<cartpole_qlearning::PhysicsEngine>& made)
{
  made = std::make_unique<cartpole_qlearning::MujocoEngine>(params, tau);
}
