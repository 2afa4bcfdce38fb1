// The YAML adapter of the config layer: a YAML document as a ParameterSource (a config file, a
// suite file, YAML text in a test), and a ParameterSink that writes one (a table's trained_with).
#pragma once

#include "cartpole_qlearning/config/parameter_source.h"
#include "cartpole_qlearning/config/section_writer.h"

#include <functional>
#include <memory>
#include <string>

namespace cartpole_qlearning
{
// A YAML document as a parameter source. Throws ConfigError when the file cannot be read or parsed.
std::unique_ptr<ParameterSource> loadYamlParameters(const std::string& path);
// The folder a config file's relative paths are relative to: the file's own ("config/x.yaml" ->
// "config", "x.yaml" -> ".", "/x.yaml" -> "/"). The nodes use it on the launch's config_file.
std::string configFolder(const std::string& path);
// (folder: what folder() answers; loadYamlParameters gives the file's.) An empty document is an
// empty map; another document that is not a map is refused saying what the root must be: the
// sections of a config file, unless `root` says otherwise ("must be a map with the keys ...").
std::unique_ptr<ParameterSource> parseYamlParameters(const std::string& text, const std::string& origin,
                                                     const std::string& folder = "");
std::unique_ptr<ParameterSource> parseYamlMap(const std::string& text, const std::string& origin,
                                              const std::string& folder, const std::string& root);

// The YAML document that `write` writes to its sink: maps in block style, lists in flow style,
// numbers exact (they read back as the same doubles), texts double-quoted; ends with a newline.
std::string yamlText(const std::function<void(ParameterSink& sink)>& write);

}  // namespace cartpole_qlearning
