#include "config_flags.h"

#include <algorithm>
#include <cctype>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"

namespace nsg::cli {
namespace {

// Flags that stand for a config key (`--score-threshold 0.5` = `--set vehicles.score_threshold=0.5`).
struct ConfigFlag {
  const char* flag;
  const char* key;
  const char* value_when_given;  // a flag without a value (--no-rgb) sets this; else nullptr
};
constexpr ConfigFlag kConfigFlags[] = {
    {"--dataroot", "dataroot", nullptr},
    {"--version", "version", nullptr},
    {"--seed", "seed", nullptr},
    {"--detections", "vehicles.detections", nullptr},
    {"--score-threshold", "vehicles.score_threshold", nullptr},
    {"--semantic-root", "camera.semantic_root", nullptr},
    {"--max-range", "lidar.max_range_m", nullptr},
    {"--no-rgb", "camera.rgb", "false"},
    {"--no-semantic", "camera.semantic", "false"},
    {"--strict", "graph.strict", "true"},
    {"--min-coverage", "crops.min_lidar_coverage", nullptr},
    {"--train-per-km2", "crops.random_per_km2", nullptr},
    {"--train-total", "crops.random_total", nullptr},
    {"--tiles-per-shard", "output.tiles_per_shard", nullptr},
    {"--deflate-level", "output.deflate_level", nullptr},
    {"--layout", "output.layout", nullptr},
};

}  // namespace

pipeline::GenerateConfig ConfigArgs::resolve(options::Origins* origins) const {
  std::vector<pipeline::ConfigAssignment> all;
  if (!locations.empty()) all.push_back({"--locations", "locations", nlohmann::json(locations).dump()});
  all.insert(all.end(), values.begin(), values.end());
  for (const std::string& s : settings) all.push_back({"--set", "", s});
  return pipeline::resolve_generate_config(config_path, all, origins);
}

void add_config_flags(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const std::vector<std::string>& flags) {
  cmd->add_option("--config", args->config_path, "Generate config JSON (defaults: samples/generate.json)");
  cmd->add_option("--set", args->settings, "Any config key: key=value (repeatable; --list-options lists the keys)");
  for (const std::string& name : flags) {
    const ConfigFlag* f = nullptr;
    for (const ConfigFlag& c : kConfigFlags)
      if (name == c.flag) f = &c;
    if (name == "--locations") {
      cmd->add_option("--locations", args->locations, "Locations to process (config locations)")->delimiter(',');
      continue;
    }
    if (f == nullptr) throw InternalError("", name, "a flag of kConfigFlags");
    const options::Option<pipeline::GenerateConfig>* opt = pipeline::generate_option_table().find(f->key);
    if (opt == nullptr) throw InternalError("", f->flag, std::string("a declared config key (") + f->key + ")");
    const std::string default_value = opt->get(pipeline::GenerateConfig{}).dump();
    if (f->value_when_given) {
      // Say what giving the flag does: "--no-rgb" sets camera.rgb to false.
      const std::string help = std::string("Sets config ") + f->key + " to " + f->value_when_given + " (default " +
                               default_value + "): " + opt->spec.description;
      cmd->add_flag_callback(
          f->flag,
          [args, f] {
            args->values.push_back({f->flag, f->key, f->value_when_given});
          },
          help);
    } else {
      const std::string help = opt->spec.description + " (config " + f->key + "; " + opt->spec.expected() +
                               ", default " + default_value + ")";
      std::string type = opt->spec.type == "choice" ? "CHOICE" : opt->spec.type == "shape" ? "JSON" : opt->spec.type;
      std::transform(type.begin(), type.end(), type.begin(), [](unsigned char c) { return std::toupper(c); });
      cmd->add_option_function<std::string>(
             f->flag,
             [args, f](const std::string& v) {
               args->values.push_back({f->flag, f->key, v});
             },
             help)
          ->type_name(type);
    }
  }
}

}  // namespace nsg::cli
