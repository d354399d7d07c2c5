// `nsgraph synth`: writes a synthetic nuScenes-format release from a world config.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>

#include "commands.h"
#include "options_listing.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/synth/config.h"
#include "nsg/synth/release.h"

namespace nsg::cli {

namespace {

struct SynthCommandOptions {
  std::string config_path;
  std::vector<std::string> settings;  // --set key=value, in order
  std::string out_dir;
  std::optional<uint64_t> seed;
  int threads = 0;
  bool print_config = false;
  bool list_options = false;
  std::string format = "text";
};

int run_synth(const SynthCommandOptions& o, const Context& ctx) {
  if (o.list_options) {
    std::cout << list_options_text(
        "synth",
        "Every key of a synthetic world config (samples/synth/*.json), as declared by the options structs; a file "
        "may give any subset.",
        synth::synth_option_table().specs(), synth::synth_option_table().to_json(synth::SynthConfig{}),
        synth::synth_config_schema(), o.format);
    return kExitOk;
  }
  options::Origins origins;
  synth::SynthConfig config = synth::resolve_synth_config(o.config_path, o.settings, &origins);
  if (o.seed) synth::synth_option_table().set(config, "seed", *o.seed, "--seed", &origins);
  if (o.print_config) {
    std::cout << config.to_json() << "\n";
    return kExitOk;
  }
  if (o.out_dir.empty()) throw ConfigError("", "--out", "an output dataroot folder");
  synth::SynthRunOptions run;
  run.out_dir = o.out_dir;
  run.threads = o.threads;
  run.progress = !ctx.quiet;
  run.validate();
  const auto start = std::chrono::steady_clock::now();
  const synth::SynthSummary s = synth::write_release(config, run);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  log::info(
      strprintf("synth: wrote %s (%s, seed %llu): %d scenes, %d samples, %d sample_data, %d annotations, "
                "%d lanes + %d connectors, %llu files, %s in %.1f s",
                o.out_dir.c_str(), config.location.c_str(), static_cast<unsigned long long>(config.seed), s.scenes,
                s.samples, s.sample_data, s.annotations, s.lanes, s.lane_connectors,
                static_cast<unsigned long long>(s.files), human_bytes(static_cast<double>(s.bytes)).c_str(), secs));
  return kExitOk;
}

}  // namespace

void add_synth_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<SynthCommandOptions>();
  CLI::App* cmd = parent.add_subcommand("synth", "Write a synthetic nuScenes-format release from a world config");
  cmd->add_option("--config", opts->config_path, "World config JSON (samples/synth/*.json; default: the defaults)");
  cmd->add_option("--set", opts->settings, "Any config key: key=value (repeatable; --list-options lists the keys)");
  cmd->add_option("--out", opts->out_dir, "Output dataroot folder");
  cmd->add_option("--seed", opts->seed, "Seed (overrides the config's \"seed\")");
  cmd->add_flag("--print-config", opts->print_config, "Print the resolved world config and exit");
  cmd->add_flag("--list-options", opts->list_options,
                "List every config key (key, type, default, unit, description) and exit");
  cmd->add_option("--format", opts->format,
                  "What --list-options prints on stdout: text, md (docs/options.md), json or schema")
      ->check(CLI::IsMember({"text", "md", "json", "schema"}));
  add_threads_option(cmd, opts->threads);
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_synth(*opts, ctx); }; });
}

}  // namespace nsg::cli
