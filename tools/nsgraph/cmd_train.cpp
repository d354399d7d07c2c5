// `nsgraph train`: the reference model (lib/model) on a dataset's split.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "options_listing.h"
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
  std::string config_path;
  std::vector<std::string> settings;  // --set key=value, in order
  // Flags that stand for config keys (unset = the config's value).
  std::optional<std::string> split, modalities, variant;
  std::optional<uint64_t> seed;
  std::optional<int> trees;
  bool print_config = false;
  bool list_options = false;
  std::string format = "text";

  void validate() const {
    NSG_CHECK(!dataset.empty(), ConfigError, "", "--dataset", "a dataset folder (manifest.json)");
    NSG_CHECK(!model.empty(), ConfigError, "", "--model", "an output file (e.g. model.yml.gz)");
    NSG_CHECK(threads >= 0, ConfigError, "", "--threads", "≥ 0 (0 = all cores)");
  }
  std::vector<model::TrainFlag> flags() const {
    std::vector<model::TrainFlag> out;
    if (split) out.push_back({"--split", "split", *split});
    if (modalities) out.push_back({"--modalities", "modalities", *modalities});
    if (variant) out.push_back({"--variant", "variant", *variant});
    if (seed) out.push_back({"--seed", "seed", *seed});
    if (trees)
      for (const char* forest : {"centre_forest", "direction_forest", "anchor_forest", "connection_forest"})
        out.push_back({"--trees", std::string(forest) + ".trees", *trees});
    return out;
  }
};

int run_train(const TrainCliOptions& o, const Context& ctx) {
  if (o.list_options) {
    std::cout << list_options_text("train",
                                   "Every option of the reference model and its training, as declared by the options "
                                   "structs; a file may give any subset.",
                                   model::train_option_table().specs(),
                                   model::train_option_table().to_json(model::TrainConfig{}),
                                   model::train_config_schema(), o.format);
    return kExitOk;
  }
  const model::TrainConfig config = model::resolve_train_config(o.config_path, o.flags(), o.settings);
  if (o.print_config) {
    std::cout << model::train_option_table().to_json(config).dump(2) << "\n";
    return kExitOk;
  }
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
  cmd->add_option("--config", opts->config_path, "Train config JSON (any subset of the keys; --list-options)");
  cmd->add_option("--set", opts->settings, "Any config key: key=value (repeatable; --list-options lists the keys)");
  cmd->add_option("--split", opts->split, "Split to train on (config key split; default train)");
  cmd->add_option("--modalities", opts->modalities,
                  "Input layers: 'all' or a comma list of lidar, rgb, semantic, vehicle (the paper's ablation; "
                  "config key modalities)");
  cmd->add_option("--variant", opts->variant,
                  "Model (the paper's Table II): b1 skeletonized centrelines, b2 anchors joined to their two "
                  "nearest neighbours, graph anchors joined by a trained has-connection classifier; recorded in "
                  "the model file (config key variant; default graph)");
  add_threads_option(cmd, opts->threads);
  cmd->add_option("--seed", opts->seed, "Seed of the pixel sampling (config key seed; default 1)");
  cmd->add_option("--trees", opts->trees,
                  "Trees per forest (sets <forest>_forest.trees; default: 32 centreline, 40 direction, 24 anchor, 60 "
                  "connection)");
  cmd->add_flag("--print-config", opts->print_config, "Print the resolved train config and exit");
  cmd->add_flag("--list-options", opts->list_options,
                "List every config key (key, type, default, unit, description) and exit");
  cmd->add_option("--format", opts->format,
                  "What --list-options prints on stdout: text, md (docs/options.md), json or schema")
      ->check(CLI::IsMember({"text", "md", "json", "schema"}));
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_train(*opts, ctx); }; });
}

}  // namespace nsg::cli
