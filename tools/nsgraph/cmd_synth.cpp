// `nsgraph synth`: writes a synthetic nuScenes-format release from a world config.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>

#include "commands.h"
#include "config_flags.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/synth/config.h"
#include "nsg/synth/release.h"

namespace nsg::cli {

namespace {

struct SynthCommandOptions {
  std::shared_ptr<ConfigArgs> config = std::make_shared<ConfigArgs>();
  std::string out_dir;
  int threads = 0;
};

int run_synth(const SynthCommandOptions& o, const Context& ctx) {
  if (list_options_if_asked(*o.config, "synth",
                            "Every key of a synthetic world config (samples/synth/*.json), as declared by the "
                            "options structs; a file may give any subset.",
                            synth::synth_option_table(), synth::synth_config_schema()))
    return kExitOk;
  const synth::SynthConfig config =
      synth::resolve_synth_config(o.config->config_path, o.config->settings, o.config->flags);
  if (print_config_if_asked(*o.config, synth::synth_option_table(), config)) return kExitOk;
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
  add_config_options(cmd, opts->config, "World config JSON (samples/synth/*.json; default: the defaults)");
  cmd->add_option("--out", opts->out_dir, "Output dataroot folder");
  add_key_flag(cmd, opts->config, synth::synth_option_table(), "--seed", "seed");
  add_threads_option(cmd, opts->threads);
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_synth(*opts, ctx); }; });
}

}  // namespace nsg::cli
