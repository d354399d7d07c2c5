// `nsgraph train`: the reference model (lib/model) on a dataset's split.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "config_flags.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/model/model.h"
#include "nsg/model/train_options.h"

namespace nsg::cli {
namespace {

struct TrainCliOptions {
  std::string dataset;
  std::string model;
  int threads = 0;
  std::shared_ptr<ConfigArgs> config = std::make_shared<ConfigArgs>();

  void validate() const {
    NSG_CHECK(!dataset.empty(), ConfigError, "", "--dataset", "a dataset folder (manifest.json)");
    NSG_CHECK(!model.empty(), ConfigError, "", "--model", "an output file (e.g. model.yml.gz)");
    NSG_CHECK(threads >= 0, ConfigError, "", "--threads", "≥ 0 (0 = all cores)");
  }
};

int run_train(const TrainCliOptions& o, const Context& ctx) {
  if (list_options_if_asked(*o.config, "train",
                            "Every option of the reference model and its training, as declared by the options "
                            "structs; a file may give any subset.",
                            model::train_option_table(), model::train_config_schema()))
    return kExitOk;
  const model::TrainConfig config =
      model::resolve_train_config(o.config->config_path, o.config->settings, o.config->flags);
  if (print_config_if_asked(*o.config, model::train_option_table(), config)) return kExitOk;
  o.validate();
  const model::ModelOptions& lib = config.model;
  const std::string& split = config.split;
  const io::Dataset dataset = io::Dataset::open(o.dataset);
  model::TrainReport r;
  const model::LaneModel m = model::LaneModel::train(dataset, split, lib, o.threads, !ctx.quiet, &r);
  m.save(o.model);
  // Figures of an empty set (no held-out tiles, no lane pixels) are NaN: say "n/a".
  auto figure = [](double v, const char* format) { return std::isnan(v) ? std::string("n/a") : strprintf(format, v); };
  log::info(strprintf(
      "trained %s on %zu tiles of '%s' (%s): features %.1f s, forests %.1f s; centreline MSE "
      "%s train / %s held out (%zu tiles); direction accuracy on lanes %s train / %s held out",
      model::to_string(lib.variant).c_str(), r.tiles, split.c_str(), lib.modalities.to_string().c_str(), r.features_s,
      r.train_s, figure(r.centre_mse_train, "%.4f").c_str(), figure(r.centre_mse_holdout, "%.4f").c_str(),
      r.holdout_tiles, figure(r.direction_accuracy_train, "%.3f").c_str(),
      figure(r.direction_accuracy_holdout, "%.3f").c_str()));
  if (lib.variant != model::Variant::kB1) {
    log::info(strprintf("anchor score MSE %s train / %s held out", figure(r.anchor_mse_train, "%.4f").c_str(),
                        figure(r.anchor_mse_holdout, "%.4f").c_str()));
  }
  if (lib.variant == model::Variant::kGraph) {
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
  cmd->add_option("--dataset", opts->dataset, "Dataset folder (manifest.json)");
  cmd->add_option("--model", opts->model, "Model file to write (.yml.gz)");
  add_config_options(cmd, opts->config, "Train config JSON (any subset of the keys; --list-options)");
  const auto& table = model::train_option_table();
  add_key_flag(cmd, opts->config, table, "--split", "split", nullptr,
               "Split to train on (config key split; default train)");
  add_key_flag(cmd, opts->config, table, "--modalities", "modalities", nullptr,
               "Input layers: 'all' (the four sensor layers) or a comma list of lidar, rgb, semantic, vehicle, "
               "prior (the paper's ablation; prior: a map-update tile's prior graph; config key modalities)");
  add_key_flag(cmd, opts->config, table, "--variant", "variant", nullptr,
               "Model (the paper's Table II): b1 skeletonized centrelines, b2 anchors joined to their two nearest "
               "neighbours, graph anchors joined by a trained has-connection classifier; recorded in the model file "
               "(config key variant; default graph)");
  add_threads_option(cmd, opts->threads);
  add_key_flag(cmd, opts->config, table, "--seed", "seed", nullptr,
               "Seed of the pixel sampling (config key seed; default 1)");
  // One flag for four keys: the trees of every forest.
  cmd->add_option_function<int>(
      "--trees",
      [config = opts->config](int trees) {
        for (const char* forest : {"centre_forest", "direction_forest", "anchor_forest", "connection_forest"})
          config->flags.push_back({"--trees", std::string(forest) + ".trees", trees});
      },
      "Trees per forest (sets <forest>_forest.trees; default: 32 centreline, 40 direction, 24 anchor, 60 "
      "connection)");
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_train(*opts, ctx); }; });
}

}  // namespace nsg::cli
