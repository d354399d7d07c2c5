// `nsgraph generate`: a release in, NuScenesGraph out (`merge` joins a distributed run's shares).
#include <chrono>
#include <iostream>
#include <optional>

#include "commands.h"
#include "config_flags.h"
#include "options_listing.h"
#include "nsg/core/error.h"
#include "nsg/core/memory.h"
#include "nsg/core/log.h"
#include "nsg/core/options.h"
#include "nsg/core/strings.h"
#include "nsg/pipeline/config.h"
#include "nsg/pipeline/generate.h"

namespace nsg::cli {
namespace {

struct GenerateCommandOptions {
  std::shared_ptr<ConfigArgs> config = std::make_shared<ConfigArgs>();
  std::string out_dir;
  std::optional<int> shard_index, num_shards;
  bool allow_empty = false;
  bool overwrite = false;
  bool check_inputs = false;
  std::string max_memory;  // "16G"; empty = the memory available (available_memory_bytes)
  int threads = 0;
};

int run_generate(const GenerateCommandOptions& o, const Context& ctx) {
  if (list_options_if_asked(*o.config, "generate",
                            "Every key of the generate config (samples/generate.json holds the defaults), as "
                            "declared by the options structs.",
                            pipeline::generate_option_table(), pipeline::generate_config_schema()))
    return kExitOk;
  const pipeline::GenerateConfig config = resolve_generate(*o.config);
  if (print_config_if_asked(*o.config, pipeline::generate_option_table(), config)) return kExitOk;
  if (o.out_dir.empty() && !o.check_inputs) throw ConfigError("", "--out", "an output folder");
  pipeline::GenerateRun run;
  run.check_inputs_only = o.check_inputs;
  run.out = o.out_dir;
  run.share = pipeline::resolve_share(o.shard_index, o.num_shards);
  run.threads = o.threads;
  run.progress = !ctx.quiet;
  run.allow_empty = o.allow_empty;
  run.overwrite = o.overwrite;
  // Refusing is the default: a run estimated beyond the machine's (or the job's) memory
  // would die of out-of-memory hours in; --max-memory sets another limit.
  run.max_memory_bytes =
      o.max_memory.empty() ? available_memory_bytes() : parse_memory_size(o.max_memory, "--max-memory");
  run.max_memory_from_machine = o.max_memory.empty();
  const auto start = std::chrono::steady_clock::now();
  const pipeline::GenerateSummary s = pipeline::generate(config, run);
  if (run.check_inputs_only) return kExitOk;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const pipeline::StageTimes& t = s.seconds;
  log::info(
      strprintf("generate: share %d of %d: %zu tiles written (%zu planned in all), %zu items done, %zu already "
                "done; %zu sweeps, %zu images; %.1f s (load %.3f, graph %.3f, lidar %.3f, plan %.3f, camera %.3f, "
                "tiles %.3f, merge %.3f)%s",
                run.share.index, run.share.count, s.tiles_written, s.tiles_planned, s.items_done, s.items_skipped,
                s.sweeps, s.images, secs, t.load_s, t.graph_s, t.lidar_s, t.plan_s, t.camera_s, t.tiles_s, t.merge_s,
                s.manifest_written ? "; manifest.json written" : "; run `nsgraph merge` when all shares are done"));
  return kExitOk;
}

}  // namespace

void add_generate_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<GenerateCommandOptions>();
  CLI::App* cmd = root.add_subcommand("generate", "Build NuScenesGraph tiles, shards and a manifest from a release");
  cmd->add_option("--out", o->out_dir, "Output dataset folder");
  add_config_options(cmd, o->config, "Generate config JSON (defaults: samples/generate.json)");
  add_generate_flags(
      cmd, o->config,
      {"--dataroot", "--version", "--locations", "--seed", "--detections", "--score-threshold", "--semantic-root",
       "--max-range", "--no-rgb", "--no-semantic", "--strict", "--min-coverage", "--train-per-km2", "--train-total",
       "--tiles-per-shard", "--deflate-level", "--layout", "--ladder"});
  cmd->add_option("--shard-index", o->shard_index, "This process's share of the work (with --num-shards)");
  cmd->add_option("--num-shards", o->num_shards, "Number of processes sharing the work");
  add_threads_option(cmd, o->threads);
  cmd->add_option("--max-memory", o->max_memory,
                  "Refuse to start when the estimated peak memory exceeds this (e.g. 16G; default: the machine's "
                  "memory, or the cgroup's limit when lower; the estimate is logged)");
  cmd->add_flag("--check-inputs", o->check_inputs,
                "Only check the inputs — the config, the tables, every map, sweep, image and mask the run would open, "
                "the memory estimate — and exit (0: complete; 2 naming the first missing file); writes nothing");
  cmd->add_flag("--allow-empty", o->allow_empty,
                "Write the dataset even when no crop passes the filters (else: exit 1 naming the filters)");
  cmd->add_flag("--overwrite", o->overwrite,
                "Remove a dataset already in --out first (manifest.json, shards/, tiles/, maps/, parts/); without it "
                "a dataset of another config there is refused and one of this config is resumed");
  cmd->callback([o, &ctx] { ctx.run = [o, &ctx] { return run_generate(*o, ctx); }; });
}

}  // namespace nsg::cli
