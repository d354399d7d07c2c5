#pragma once
// The config on a command line, one front end for every command with a declared config
// (generate, inspect layers, synth, train, frames): --config, --set, --print-config,
// --list-options / --format, and flags that stand for config keys. Each key flag's help is
// its key's declared description and default; values are checked by the declarations,
// naming the flag and the key. The precedence is options::resolve_config's: the defaults,
// the file, each --set, then the key flags (docs/options.md).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/options.h"
#include "nsg/pipeline/config.h"
#include "options_listing.h"

namespace nsg::cli {

struct ConfigArgs {
  std::string config_path;
  std::vector<std::string> settings;      // --set key=value, in order
  std::vector<options::FlagValue> flags;  // key flags, in command-line order
  bool print_config = false;
  bool list_options = false;
  std::string format = "text";  // of --list-options
};

// --config (described by `config_help`) and --set; with `listing`, also --print-config,
// --list-options and --format.
void add_config_options(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const std::string& config_help,
                        bool listing = true);

// A flag that stands for `key` of `table`. With `value_when_given` it takes no value and
// sets the key to that JSON ("false" for --no-rgb); else its text is the key's value
// (options::flag_text_value). `help` replaces the generated help when not empty.
template <typename Owner>
void add_key_flag(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const options::Table<Owner>& table,
                  const std::string& flag, const std::string& key, const char* value_when_given = nullptr,
                  const std::string& help = "") {
  const options::Option<Owner>* opt = table.find(key);
  if (opt == nullptr) throw InternalError("", flag, "a declared config key (" + key + ")");
  const std::string default_value = opt->get(Owner{}).dump();
  if (value_when_given != nullptr) {
    // Say what giving the flag does: "--no-rgb" sets camera.rgb to false.
    const std::string text = help.empty() ? "Sets config " + key + " to " + value_when_given + " (default " +
                                                default_value + "): " + opt->spec.description
                                          : help;
    const options::Json value = options::Json::parse(value_when_given);
    cmd->add_flag_callback(
        flag,
        [args, flag, key, value] {
          args->flags.push_back({flag, key, value});
        },
        text);
    return;
  }
  const std::string text = help.empty() ? opt->spec.description + " (config " + key + "; " + opt->spec.expected() +
                                              ", default " + default_value + ")"
                                        : help;
  std::string type = opt->spec.type == "choice" ? "CHOICE" : opt->spec.type == "shape" ? "JSON" : opt->spec.type;
  std::transform(type.begin(), type.end(), type.begin(), [](unsigned char c) { return std::toupper(c); });
  const options::Spec spec = opt->spec;
  cmd->add_option_function<std::string>(
         flag,
         [args, flag, key, spec](const std::string& v) {
           args->flags.push_back({flag, key, options::flag_text_value(spec, v)});
         },
         text)
      ->type_name(type);
}

// --list-options: prints the listing of `table` on stdout and returns true; false when not asked.
template <typename Owner>
bool list_options_if_asked(const ConfigArgs& args, const std::string& command, const std::string& intro,
                           const options::Table<Owner>& table, const options::OrderedJson& schema) {
  if (!args.list_options) return false;
  std::cout << list_options_text(command, intro, table.specs(), table.to_json(Owner{}), schema, args.format);
  return true;
}

// --print-config: prints the resolved config (declaration order) and returns true.
template <typename Owner>
bool print_config_if_asked(const ConfigArgs& args, const options::Table<Owner>& table, const Owner& config) {
  if (!args.print_config) return false;
  std::cout << table.to_json(config).dump(2) << "\n";
  return true;
}

// The generate config's key flags (generate, inspect layers) by name: "--dataroot",
// "--locations", "--no-rgb", … (config_flags.cpp lists them).
void add_generate_flags(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const std::vector<std::string>& flags);
// pipeline::resolve_generate_config of the command line.
pipeline::GenerateConfig resolve_generate(const ConfigArgs& args, options::Origins* origins = nullptr);

}  // namespace nsg::cli
