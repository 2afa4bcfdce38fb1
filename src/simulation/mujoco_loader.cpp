// The MuJoCo engine as the registry knows it (engine_registry.h): its keys, and how it loads. The
// engine itself (mujoco_engine.cpp) is a library of its own, built when CMake finds MuJoCo and
// loaded the first time a config asks for it; this file is built either way, so that a build
// without MuJoCo still knows the name and says how to get it.
#include "cartpole_qlearning/simulation/engine_registry.h"
#include "cartpole_qlearning/simulation/physics_engines.h"

#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
#include <dlfcn.h>

#include <mutex>
#endif

#include <string>

namespace cartpole_qlearning
{
namespace
{
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
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
#endif

std::unique_ptr<PhysicsEngine> makeMujocoEngine(const CartPoleParams& physics, const EngineParams& engine)
{
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
  std::unique_ptr<PhysicsEngine> made;
  mujocoFactory()(engine, physics.tau, made);
  return made;
#else
  (void)physics;
  (void)engine;
  throw EngineError(
      "physics/engine = 'mujoco' is not available: cartpole_qlearning was built without MuJoCo. "
      "Install it (Debian 12: sudo apt-get install libmujoco-dev, or scripts/setup.sh), then "
      "rebuild (catkin_make): CMake finds it and builds the MuJoCo engine");
#endif
}
}  // namespace

bool mujocoAvailable()
{
#ifdef CARTPOLE_QLEARNING_WITH_MUJOCO
  return true;
#else
  return false;
#endif
}

EngineDescription mujocoEngineDescription()
{
  EngineDescription d;
  d.name = "mujoco";
  d.keys = {EngineKey{"model", nullptr, nullptr, &EngineParams::model, "an MJCF file"},
            EngineKey{"cart_joint", nullptr, nullptr, &EngineParams::cart_joint, ""},
            EngineKey{"pole_joint", nullptr, nullptr, &EngineParams::pole_joint, ""},
            EngineKey{"actuator", nullptr, nullptr, &EngineParams::actuator, ""}};
  d.foreign_keys_note = "the model sets it: edit the model";
  d.own_keys_note = "it names a MuJoCo model's parts";
  d.names_joints = true;
  // A model's pole is its geometry. Its episodes are not shown independent of the ones before
  // (and replaying one alone would load the model for it); its XML loading is not documented as
  // thread-safe.
  d.scales_half_length = false;
  d.episodes_independent = false;
  d.makes_in_parallel = false;
  d.describe = [](const CartPoleParams&, const EngineParams& engine) { return "MuJoCo model " + engine.model; };
  d.make = makeMujocoEngine;
  return d;
}

}  // namespace cartpole_qlearning
