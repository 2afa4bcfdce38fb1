#include "cartpole_qlearning/simulation/physics_engines.h"

#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
#include <dlfcn.h>

#include <mutex>
#include <string>
#endif

namespace cartpole_qlearning
{
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
namespace
{
using MakeMujocoEngine = void (*)(const EngineParams&, double, std::unique_ptr<PhysicsEngine>&);

// The MuJoCo engine's library, loaded when a config first asks for it rather than at every start:
// libmujoco alone took about 7 ms of CPU to load and relocate, a third of a train_headless run that
// never steps a model. It lies beside this library (devel or install space alike).
MakeMujocoEngine mujocoFactory()
{
  static std::once_flag once;
  static MakeMujocoEngine factory = nullptr;
  static std::string error;
  std::call_once(once, [] {
    Dl_info self{};
    std::string path = CARTPOLE_QLEARNING_MUJOCO_LIBRARY;
    if (::dladdr(reinterpret_cast<void*>(&mujocoAvailable), &self) != 0 && self.dli_fname != nullptr)
    {
      const std::string here = self.dli_fname;
      const std::size_t slash = here.rfind('/');
      if (slash != std::string::npos)
        path = here.substr(0, slash + 1) + path;
    }
    void* library = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (library != nullptr)
      factory = reinterpret_cast<MakeMujocoEngine>(::dlsym(library, "cartpole_qlearning_make_mujoco_engine"));
    if (factory == nullptr)
    {
      const char* why = ::dlerror();
      error = "physics/engine = 'mujoco': the MuJoCo engine's library " + path + " cannot be loaded (" +
              (why != nullptr ? why : "no reason given") + "): rebuild cartpole_qlearning (catkin_make)";
    }
  });
  if (factory == nullptr)
    throw EngineError(error);
  return factory;
}
}  // namespace
#endif

bool mujocoAvailable()
{
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
  return true;
#else
  return false;
#endif
}

std::unique_ptr<PhysicsEngine> makePhysicsEngine(const CartPoleParams& physics, const EngineParams& engine)
{
  if (engine.kind == EngineKind::Equations)
    return std::make_unique<EquationsEngine>(physics);
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
  std::unique_ptr<PhysicsEngine> made;
  mujocoFactory()(engine, physics.tau, made);
  return made;
#else
  throw EngineError(
      "physics/engine = 'mujoco' is not available: cartpole_qlearning was built without MuJoCo. "
      "Install it (Debian 12: sudo apt-get install libmujoco-dev, or scripts/setup.sh), then "
      "rebuild (catkin_make): CMake finds it and builds the MuJoCo engine");
#endif
}

CartPoleSimulation makeSimulation(const CartPoleParams& physics, const EngineParams& engine, double start_state_bound,
                                  std::uint64_t seed, const PerturbationParams& perturbations)
{
  return CartPoleSimulation(makePhysicsEngine(physics, engine), start_state_bound, seed, perturbations);
}

}  // namespace cartpole_qlearning
