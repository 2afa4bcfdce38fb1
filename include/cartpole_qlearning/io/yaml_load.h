// YAML text parsed alike on every yaml-cpp this package builds with. Before 0.7 (0.6.3 on Debian
// 11, 0.6.2 on Noetic's Ubuntu 20.04), YAML::Load never returns on a ':' that ends an entry of a
// flow collection ("[:", "{a:]", "q: [[:"): its scanner makes an empty scalar there over and over,
// allocating as it goes, until the machine runs out of memory (jbeder/yaml-cpp#499 and #899, fixed
// by #911 in 0.7.0). A table file, config or run record one typo away from that would hang the
// node that reads it; the fuzzers found it in seconds. loadYaml refuses such text on those
// versions with the ParserException a newer yaml-cpp throws for it, so every reader's own refusal
// (a clear error, the table in use untouched) applies.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

namespace cartpole_qlearning
{
// Where, in `text`, yaml-cpp before 0.7 would loop for ever: the first ':' inside a flow
// collection ([...] or {...}, outside quotes and comments) followed by ']' or by the end of the
// text. nullopt for text with none. (Checked on every version, so that its tests run everywhere.)
std::optional<YAML::Mark> flowColonOldYamlCppLoopsOn(const std::string& text);

// YAML::Load(text), but for text that flowColonOldYamlCppLoopsOn finds, which throws
// YAML::ParserException at that mark when this build's yaml-cpp is older than 0.7. (0.7 and later
// refuse most such text themselves; "[a:]", a one-pair mapping in a list, they read.)
YAML::Node loadYaml(const std::string& text);

// Whether loadYaml refuses that text first (this build's yaml-cpp is older than 0.7).
bool loadYamlGuardsFlowColons();

}  // namespace cartpole_qlearning
