// libFuzzer target: the config reader (the YAML file train_headless reads, and the checks the
// nodes apply to the parameter server). Whatever the bytes, it returns a valid config or throws
// ConfigError; any other exception, a crash or a sanitizer report is a bug. An accepted config
// must make a training session (no exception from the core for values the reader let through).
#include "cartpole_qlearning/learning/training_config.h"
#include "cartpole_qlearning/learning/training_session.h"

#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  using namespace cartpole_qlearning;
  const std::string text(reinterpret_cast<const char*>(data), size);
  TrainingConfig config;
  try
  {
    const auto source = parseYamlParameters(text, "fuzz.yaml");
    refuseUnknownSections(*source);
    config = readTrainingConfig(*source);
  }
  catch (const ConfigError&)
  {
    return 0;
  }
  TrainingSession session(config.task, config.agent, 0);
  session.beginEpisode(CartPoleState::Zero());
  session.observe(CartPoleState::Constant(0.01));
  return 0;
}
