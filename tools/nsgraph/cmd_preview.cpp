// `nsgraph preview`: PNG mosaics of a dataset's shards, per-location overviews and
// submission overlays (lib/preview).
#include <memory>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/preview/preview.h"

namespace nsg::cli {
namespace {

struct PreviewCliOptions {
  std::string dataset;
  std::string out;
  int shard = -1;  // -1 = every shard
  preview::PreviewOptions lib;

  void validate() const {
    NSG_CHECK(!out.empty(), ConfigError, "", "--out", "an output folder");
    NSG_CHECK(shard >= -1, ConfigError, "", "--shard", "a shard number ≥ 0");
  }
};

int run_preview(PreviewCliOptions o) {
  o.validate();
  if (o.shard >= 0) o.lib.shard = o.shard;
  preview::write_previews(o.dataset, o.out, o.lib);
  return kExitOk;
}

}  // namespace

void add_preview_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<PreviewCliOptions>();
  opts->lib.progress = true;
  CLI::App* cmd = parent.add_subcommand("preview", "PNG previews of a dataset or a submission for checking by eye");
  cmd->add_option("dataset,--dataset", opts->dataset, "Dataset folder (manifest.json)")->required();
  cmd->add_option("--out", opts->out, "Folder for the PNGs")->required();
  cmd->add_option("--split", opts->lib.split,
                  "Only this split (default: all; with --submission the split its keys are tiles of)");
  cmd->add_option("--shard", opts->shard, "Only the shard numbered N (<split>-NNNNNN)");
  cmd->add_option("--max-tiles", opts->lib.max_tiles, "Tiles per image (the first K, or the worst K with --sort)")
      ->capture_default_str();
  cmd->add_flag("--overview", opts->lib.overview,
                "One PNG per location: LiDAR coverage, split regions, crops, lane graph");
  cmd->add_option("--submission", opts->lib.submission,
                  "Submission JSON: ground truth (blue) and prediction (orange) per tile, with scores");
  cmd->add_option("--sort", opts->lib.sort, "With --submission: order by this metric, worst first (e.g. apls)");
  cmd->callback([opts, &ctx]() { ctx.run = [opts]() { return run_preview(*opts); }; });
}

}  // namespace nsg::cli
