// `nsgraph generate` and `nsgraph merge` (issue 6): a release in, NuScenesGraph out.
#include <chrono>
#include <iostream>
#include <optional>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/memory.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/pipeline/config.h"
#include "nsg/pipeline/generate.h"
#include "nsg/pipeline/stats.h"

namespace nsg::cli {
namespace {

// Command-line values; each one set overrides the config file.
struct GenerateCommandOptions {
  std::string config_path;
  std::string out_dir;
  std::optional<std::string> dataroot, version, detections, semantic_root, layout;
  std::vector<std::string> locations;
  std::optional<uint64_t> seed;
  std::optional<double> min_coverage, train_per_km2, score_threshold, max_range;
  std::optional<int64_t> tiles_per_shard, train_total;
  std::optional<int> shard_index, num_shards, deflate_level;
  bool no_rgb = false, no_semantic = false, strict = false;
  std::vector<std::string> settings;  // --set key.path=value
  bool print_config = false;
  bool allow_empty = false;
  std::string max_memory;  // "16G"; empty = no limit
  int threads = 0;

  pipeline::GenerateConfig resolve() const {
    pipeline::GenerateConfig c = config_path.empty() ? pipeline::GenerateConfig{}
                                                     : pipeline::load_generate_config(config_path);
    if (dataroot) c.dataroot = *dataroot;
    if (version) c.version = *version;
    if (!locations.empty()) c.locations = locations;
    if (seed) c.seed = *seed;
    if (detections) c.raster.detections_file = *detections;
    if (score_threshold) c.raster.detection_score_threshold = *score_threshold;
    if (semantic_root) c.raster.camera.semantic_root = *semantic_root;
    if (max_range) c.raster.lidar.max_range_m = *max_range;
    if (no_rgb) c.raster.camera.rgb = false;
    if (no_semantic) c.raster.camera.semantic = false;
    if (strict) c.graph.strict = true;
    if (min_coverage) c.crops.min_lidar_coverage = *min_coverage;
    if (train_per_km2) c.crops.random_per_km2 = *train_per_km2;
    if (train_total) c.crops.random_total = *train_total;
    if (tiles_per_shard) c.output.tiles_per_shard = *tiles_per_shard;
    if (deflate_level) c.output.deflate_level = *deflate_level;
    if (layout) {
      if (*layout != "tar" && *layout != "folder") throw ConfigError("", "--layout", "'tar' or 'folder'");
      c.output.layout = *layout == "tar" ? pipeline::Layout::kTar : pipeline::Layout::kFolder;
    }
    for (const std::string& s : settings) pipeline::apply_setting(c, s);
    return c;
  }
};

int run_generate(const GenerateCommandOptions& o, const Context& ctx) {
  const pipeline::GenerateConfig config = o.resolve();
  if (o.print_config) {
    config.validate(/*require_inputs=*/false);
    std::cout << pipeline::config_to_json(config).dump(2) << "\n";
    return kExitOk;
  }
  if (o.out_dir.empty()) throw ConfigError("", "--out", "an output folder");
  pipeline::GenerateRun run;
  run.out = o.out_dir;
  run.share = pipeline::resolve_share(o.shard_index, o.num_shards);
  run.threads = o.threads;
  run.progress = !ctx.quiet;
  run.allow_empty = o.allow_empty;
  if (!o.max_memory.empty()) run.max_memory_bytes = parse_memory_size(o.max_memory, "--max-memory");
  const auto start = std::chrono::steady_clock::now();
  const pipeline::GenerateSummary s = pipeline::generate(config, run);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const pipeline::StageTimes& t = s.seconds;
  log::info(strprintf("generate: share %d of %d: %zu tiles written (%zu planned in all), %zu items done, %zu already "
                      "done; %zu sweeps, %zu images; %.1f s (load %.3f, graph %.3f, lidar %.3f, plan %.3f, camera %.3f, "
                      "tiles %.3f, merge %.3f)%s",
                      run.share.index, run.share.count, s.tiles_written, s.tiles_planned, s.items_done, s.items_skipped,
                      s.sweeps, s.images, secs, t.load_s, t.graph_s, t.lidar_s, t.plan_s, t.camera_s, t.tiles_s,
                      t.merge_s, s.manifest_written ? "; manifest.json written" : "; run `nsgraph merge` when all shares are done"));
  return kExitOk;
}

}  // namespace

void add_generate_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<GenerateCommandOptions>();
  CLI::App* cmd = root.add_subcommand("generate", "Build NuScenesGraph tiles, shards and a manifest from a release");
  cmd->add_option("--config", o->config_path, "Generate config JSON (defaults: samples/generate.json)");
  cmd->add_option("--out", o->out_dir, "Output dataset folder");
  cmd->add_option("--dataroot", o->dataroot, "nuScenes dataroot");
  cmd->add_option("--version", o->version, "Release version (v1.0-mini, v1.0-trainval, ...)");
  cmd->add_option("--locations", o->locations, "Locations to process (default: all in the release)")->delimiter(',');
  cmd->add_option("--seed", o->seed, "Seed of splits and crops");
  cmd->add_option("--detections", o->detections, "nuScenes detection results JSON for the vehicle layer");
  cmd->add_option("--score-threshold", o->score_threshold, "Keep detections with score ≥ this");
  cmd->add_option("--semantic-root", o->semantic_root, "Semantic masks root (default <dataroot>/semantic)");
  cmd->add_option("--max-range", o->max_range, "LiDAR max range, metres");
  cmd->add_flag("--no-rgb", o->no_rgb, "Skip camera colours");
  cmd->add_flag("--no-semantic", o->no_semantic, "Skip semantic masks");
  cmd->add_flag("--strict", o->strict, "Map defects are errors");
  cmd->add_option("--min-coverage", o->min_coverage, "Keep crops with at least this LiDAR coverage fraction");
  cmd->add_option("--train-per-km2", o->train_per_km2, "Random train crops per km² of covered area");
  cmd->add_option("--train-total", o->train_total, "Random train crops in total per location (overrides per km²)");
  cmd->add_option("--tiles-per-shard", o->tiles_per_shard, "Tiles per shard (0 = from the target shard size)");
  cmd->add_option("--deflate-level", o->deflate_level, "GeoTIFF deflate level 1-9");
  cmd->add_option("--layout", o->layout, "tar (WebDataset shards) or folder");
  cmd->add_option("--set", o->settings, "Any config value: key.path=value (repeatable)");
  cmd->add_option("--shard-index", o->shard_index, "This process's share of the work (with --num-shards)");
  cmd->add_option("--num-shards", o->num_shards, "Number of processes sharing the work");
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
  cmd->add_flag("--print-config", o->print_config, "Print the resolved config and exit");
  cmd->add_option("--max-memory", o->max_memory,
                  "Refuse to start when the estimated peak memory exceeds this (e.g. 16G; the estimate is logged)");
  cmd->add_flag("--allow-empty", o->allow_empty,
                "Write the dataset even when no crop passes the filters (else: exit 1 naming the filters)");
  cmd->callback([o, &ctx] { ctx.run = [o, &ctx] { return run_generate(*o, ctx); }; });
}

void add_merge_command(CLI::App& root, Context& ctx) {
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = root.add_subcommand("merge", "Check the shares of a distributed generate run and write manifest.json");
  cmd->add_option("--out", *out, "The dataset folder all shares wrote to")->required();
  cmd->callback([out, &ctx] {
    ctx.run = [out] {
      pipeline::merge(*out);
      log::info("merge: " + *out + "/manifest.json written");
      return kExitOk;
    };
  });
}

void add_stats_command(CLI::App& root, Context& ctx) {
  struct StatsOptions {
    std::string dataset;
    bool json = false;
  };
  auto o = std::make_shared<StatsOptions>();
  CLI::App* cmd = root.add_subcommand("stats", "A dataset's key figures per split (the paper's Table I fields)");
  cmd->add_option("dataset", o->dataset, "Dataset folder (holds manifest.json)")->required();
  cmd->add_flag("--json", o->json, "JSON instead of a text table");
  cmd->callback([o, &ctx] {
    ctx.run = [o] {
      const pipeline::DatasetStats stats = pipeline::compute_stats(o->dataset);
      if (o->json)
        std::cout << pipeline::stats_json(stats).dump(2) << "\n";
      else
        std::cout << pipeline::stats_text(stats);
      return kExitOk;
    };
  });
}

}  // namespace nsg::cli
