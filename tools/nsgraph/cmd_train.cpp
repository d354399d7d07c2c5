// `nsgraph train`: the reference model (lib/model) on a dataset's split.
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/model/model.h"

namespace nsg::cli {
namespace {

struct TrainCliOptions {
  std::string dataset;
  std::string split = "train";
  std::string model;
  std::string modalities = "all";
  std::string variant = "graph";
  int threads = 0;
  uint64_t seed = 1;
  int trees = -1;  // -1 = the forests' defaults
  model::ModelOptions lib;

  void validate() const {
    NSG_CHECK(!model.empty(), ConfigError, "", "--model", "an output file (e.g. model.yml.gz)");
    NSG_CHECK(threads >= 0, ConfigError, "", "--threads", "≥ 0 (0 = all cores)");
    NSG_CHECK(trees == -1 || trees >= 1, ConfigError, "", "--trees", "≥ 1");
  }
};

int run_train(TrainCliOptions o, const Context& ctx) {
  o.validate();
  o.lib.variant = model::parse_variant(o.variant);
  o.lib.modalities = model::Modalities::parse(o.modalities);
  o.lib.seed = o.seed;
  if (o.trees > 0) o.lib.centre.trees = o.lib.direction.trees = o.lib.anchor.trees = o.lib.connection.trees = o.trees;
  o.lib.validate();
  const io::Dataset dataset = io::Dataset::open(o.dataset);
  model::TrainReport r;
  const model::LaneModel m = model::LaneModel::train(dataset, o.split, o.lib, o.threads, !ctx.quiet, &r);
  m.save(o.model);
  // Figures of an empty set (no held-out tiles, no lane pixels) are NaN: say "n/a".
  auto figure = [](double v, const char* format) { return std::isnan(v) ? std::string("n/a") : strprintf(format, v); };
  log::info(strprintf(
      "trained %s on %zu tiles of '%s' (%s): features %.1f s, forests %.1f s; centreline MSE "
      "%s train / %s held out (%zu tiles); direction accuracy on lanes %s train / %s held out",
      model::to_string(o.lib.variant).c_str(), r.tiles, o.split.c_str(), o.lib.modalities.to_string().c_str(),
      r.features_s, r.train_s, figure(r.centre_mse_train, "%.4f").c_str(), figure(r.centre_mse_holdout, "%.4f").c_str(),
      r.holdout_tiles, figure(r.direction_accuracy_train, "%.3f").c_str(),
      figure(r.direction_accuracy_holdout, "%.3f").c_str()));
  if (o.lib.variant != model::Variant::kB1) {
    log::info(strprintf("anchor score MSE %s train / %s held out", figure(r.anchor_mse_train, "%.4f").c_str(),
                        figure(r.anchor_mse_holdout, "%.4f").c_str()));
  }
  if (o.lib.variant == model::Variant::kGraph) {
    log::info(strprintf("connection classifier: %zu pairs (%zu connected), %.1f s; accuracy %s train / %s held out",
                        r.pair_samples, r.pair_positives, r.pairs_s, figure(r.pair_accuracy_train, "%.3f").c_str(),
                        figure(r.pair_accuracy_holdout, "%.3f").c_str()));
  }
  log::info("model written to " + o.model);
  return kExitOk;
}

}  // namespace

void add_train_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<TrainCliOptions>();
  CLI::App* cmd = parent.add_subcommand("train", "Train the reference lane-graph model on a dataset split");
  cmd->add_option("--dataset", opts->dataset, "Dataset folder (manifest.json)")->required();
  cmd->add_option("--split", opts->split, "Split to train on")->capture_default_str();
  cmd->add_option("--model", opts->model, "Model file to write (.yml.gz)")->required();
  cmd->add_option("--modalities", opts->modalities,
                  "Input layers: 'all' or a comma list of lidar, rgb, semantic, vehicle (the paper's ablation)")
      ->capture_default_str();
  cmd->add_option("--variant", opts->variant,
                  "Model (the paper's Table II): b1 skeletonized centrelines, b2 anchors joined to their two "
                  "nearest neighbours, graph anchors joined by a trained has-connection classifier; recorded in "
                  "the model file")
      ->capture_default_str();
  cmd->add_option("--threads", opts->threads, "Worker threads (0 = all cores; results do not depend on it)")
      ->capture_default_str();
  cmd->add_option("--seed", opts->seed, "Seed of the pixel sampling")->capture_default_str();
  cmd->add_option("--trees", opts->trees,
                  "Trees per forest (default: 32 centreline, 40 direction, 24 anchor, 60 connection)");
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_train(*opts, ctx); }; });
}

}  // namespace nsg::cli
