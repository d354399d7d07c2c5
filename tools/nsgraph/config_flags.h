#pragma once
// The generate config on a command line (generate, inspect layers): --config, --set and
// flags that stand for config keys. Each flag's help is its key's declared description;
// values are checked by the declarations, naming the flag and the key.
#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

#include "nsg/pipeline/config.h"

namespace nsg::cli {

struct ConfigArgs {
  std::string config_path;
  std::vector<pipeline::ConfigAssignment> values;  // in command-line order: flags, then --set
  std::vector<std::string> settings;               // --set key=value
  std::vector<std::string> locations;              // --locations a,b

  // Defaults, the file, the flags, then --set; the relations last.
  pipeline::GenerateConfig resolve(options::Origins* origins = nullptr) const;
};

// Adds --config, --set and the config flags named in `flags` (see config_flags.cpp).
void add_config_flags(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const std::vector<std::string>& flags);

}  // namespace nsg::cli
