#include "config_flags.h"

namespace nsg::cli {
namespace {

// Flags that stand for a generate config key (`--score-threshold 0.5` = `--set vehicles.score_threshold=0.5`).
struct GenerateFlag {
  const char* flag;
  const char* key;
  const char* value_when_given;  // a flag without a value (--no-rgb) sets this; else nullptr
};
constexpr GenerateFlag kGenerateFlags[] = {
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
    {"--ladder", "ladder.rungs", pipeline::kDefaultLadderRungs},
};

}  // namespace

void add_config_options(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const std::string& config_help,
                        bool listing) {
  cmd->add_option("--config", args->config_path, config_help);
  cmd->add_option("--set", args->settings, "Any config key: key=value (repeatable; --list-options lists the keys)");
  if (!listing) return;
  cmd->add_flag("--print-config", args->print_config, "Print the resolved config and exit");
  cmd->add_flag("--list-options", args->list_options,
                "List every config key (key, type, default, unit, description) and exit");
  cmd->add_option("--format", args->format,
                  "What --list-options prints on stdout: text, md (docs/options.md), json or schema")
      ->check(CLI::IsMember({"text", "md", "json", "schema"}));
}

void add_generate_flags(CLI::App* cmd, const std::shared_ptr<ConfigArgs>& args, const std::vector<std::string>& flags) {
  for (const std::string& name : flags) {
    if (name == "--locations") {
      // A comma list on the command line, a JSON array in the config.
      cmd->add_option_function<std::vector<std::string>>(
             "--locations",
             [args](const std::vector<std::string>& v) {
               args->flags.push_back({"--locations", "locations", options::Json(v)});
             },
             "Locations to process (config locations)")
          ->delimiter(',');
      continue;
    }
    const GenerateFlag* f = nullptr;
    for (const GenerateFlag& g : kGenerateFlags)
      if (name == g.flag) f = &g;
    if (f == nullptr) throw InternalError("", name, "a flag of kGenerateFlags");
    add_key_flag(cmd, args, pipeline::generate_option_table(), f->flag, f->key, f->value_when_given);
  }
}

pipeline::GenerateConfig resolve_generate(const ConfigArgs& args, options::Origins* origins) {
  return pipeline::resolve_generate_config(args.config_path, args.settings, args.flags, origins);
}

}  // namespace nsg::cli
