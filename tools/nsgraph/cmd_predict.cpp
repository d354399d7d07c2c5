// `nsgraph predict`: the reference model's lane graphs for a dataset split, as a
// submission (schemas/v1/submission.schema.json). A model ending in .onnx is LaneGraphNet
// exported by `python -m nsgraph.models.export`, run through OpenCV dnn (lib/model onnx_net).
#include <chrono>
#include <memory>
#include <optional>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/core/atomic_file.h"
#include "nsg/frames/from_tiles.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/io.h"
#include "nsg/model/copy_prior.h"
#include "nsg/model/model.h"
#include "nsg/model/onnx_net.h"

namespace nsg::cli {
namespace {

struct PredictCliOptions {
  std::string model;
  std::string dataset;
  std::string split = "test";
  std::string out;
  std::string frames;   // --frames: an `nsgraph frames` export of the dataset; write its results instead
  bool ladder = false;  // --ladder: the split and every rung of it in one submission
  int threads = 0;

  void validate() const {
    NSG_CHECK(!out.empty(), ConfigError, "", "--out", "a submission file to write");
    NSG_CHECK(threads >= 0, ConfigError, "", "--threads", "≥ 0 (0 = all cores)");
    NSG_CHECK(!ladder || frames.empty(), ConfigError, "", "--ladder", "tile predictions (not with --frames)");
    NSG_CHECK(!ladder || !io::rung_split(split), ConfigError, "", "--ladder",
              "a split (train, val, test) whose rungs it predicts, not the rung '" + split + "'");
  }
};

bool is_onnx(const std::string& path) { return ends_with(path, ".onnx"); }
// --model prior: the copy-the-prior baseline of a map-update dataset (no model file).
bool is_copy_prior(const std::string& model) { return model == "prior"; }

// --frames: the export's frames of the split, read (every record checked, a defect named by
// file and JSON pointer) before the model runs, so a bad export costs no prediction.
frames::ExportFrames read_frames_of_dataset(const PredictCliOptions& o, const io::Dataset& dataset) {
  frames::ExportFrames ex = frames::read_export_frames(o.frames, o.split);
  NSG_CHECK(ex.dataset_manifest_sha256 == sha256_file(dataset.root() / "manifest.json"), DataError,
            (std::filesystem::path(o.frames) / "manifest.json").string(), "/source/dataset_manifest_sha256",
            "the frames export of --dataset " + o.dataset + " (its manifest's sha256)");
  return ex;
}

// --frames: the tiles' graphs stitched and cut around each frame of the export's split,
// written as an OpenLane-V2 results document (docs/frames.md "The tile baseline").
int write_frame_results(const PredictCliOptions& o, const frames::ExportFrames& ex, const io::Dataset& dataset,
                        const metrics::GraphSet& graphs, const std::string& model_name) {
  std::vector<frames::TilePrediction> tiles;
  double resolution_m = 0.2;
  dataset.for_each_tile(o.split, [&](const io::DatasetTile& tile) {
    const io::TileMeta meta = tile.meta();
    frames::TilePrediction t;
    t.key = tile.key;
    t.location = meta.location;
    t.bounds_m = meta.bounds_m;
    resolution_m = meta.resolution_m;
    const auto it = graphs.find(tile.key);
    if (it != graphs.end()) t.graph = it->second;
    tiles.push_back(std::move(t));
    return true;
  });
  const nlohmann::ordered_json results =
      frames::tiles_to_frame_results(tiles, ex, resolution_m, "nsgraph " + model_name + " (tiles stitched)");
  write_file_atomic(o.out, results.dump() + "\n");
  log::info(strprintf("predicted %zu frames of '%s' from %zu tiles (%s) → %s", ex.frames.size(), o.split.c_str(),
                      tiles.size(), model_name.c_str(), o.out.c_str()));
  return kExitOk;
}

// --split, and with --ladder every rung of it the dataset holds ("<split>-r<k>"), so one
// submission scores the whole ladder (score's per-rung report).
std::vector<std::string> splits_to_predict(const PredictCliOptions& o, const io::Dataset& dataset) {
  std::vector<std::string> splits = {o.split};
  if (!o.ladder) return splits;
  dataset.require_split(o.split);
  for (const std::string& name : dataset.split_names())
    if (const auto rung = io::rung_split(name); rung && rung->first == o.split) splits.push_back(name);
  NSG_CHECK(splits.size() > 1, DataError, (dataset.root() / "manifest.json").string(), "--ladder",
            "a dataset with an observation ladder on split '" + o.split + "' (generate --ladder); it has none");
  return splits;
}

int run_predict(const PredictCliOptions& o, const Context& ctx) {
  o.validate();
  std::optional<model::LaneModel> forest;
  if (!is_onnx(o.model) && !is_copy_prior(o.model)) forest = model::LaneModel::load(o.model);
  const io::Dataset dataset = io::Dataset::open(o.dataset);
  std::optional<frames::ExportFrames> export_frames;
  if (!o.frames.empty()) export_frames = read_frames_of_dataset(o, dataset);
  const auto t0 = std::chrono::steady_clock::now();
  metrics::GraphSet graphs;
  for (const std::string& split : splits_to_predict(o, dataset)) {
    metrics::GraphSet part = forest ? model::predict_dataset(*forest, dataset, split, o.threads, !ctx.quiet)
                             : is_copy_prior(o.model)
                                 ? model::copy_prior_dataset(dataset, split)
                                 : model::predict_dataset_onnx(o.model, dataset, split, o.threads, !ctx.quiet);
    graphs.merge(part);  // rung keys (<key>-r<k>) never equal a split's keys
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string model_name = forest                   ? model::to_string(forest->options().variant)
                                 : is_copy_prior(o.model) ? std::string("copy-the-prior")
                                                          : std::string("LaneGraphNet (ONNX)");
  if (export_frames) return write_frame_results(o, *export_frames, dataset, graphs, model_name);
  metrics::write_submission(graphs, o.out);
  size_t nodes = 0, edges = 0;
  for (const auto& [key, g] : graphs) {
    nodes += g.nodes.size();
    edges += g.edges.size();
  }
  log::info(
      strprintf("predicted %zu tiles of '%s' with the %s model in %.1f s (%.1f tiles/s): %zu nodes, "
                "%zu edges → %s",
                graphs.size(), o.split.c_str(), model_name.c_str(), s, graphs.size() / std::max(s, 1e-9), nodes, edges,
                o.out.c_str()));
  return kExitOk;
}

}  // namespace

void add_predict_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<PredictCliOptions>();
  CLI::App* cmd = parent.add_subcommand("predict", "Predict lane graphs for a dataset split with a trained model");
  cmd->add_option("--model", opts->model,
                  "Model file from `nsgraph train`, LaneGraphNet's M.onnx (M.pairs.onnx next to it), or \"prior\": "
                  "a map-update dataset's copy-the-prior baseline (each tile's prior graph)")
      ->required();
  cmd->add_option("--dataset", opts->dataset, "Dataset folder (manifest.json)")->required();
  cmd->add_option("--split", opts->split, "Split to predict")->capture_default_str();
  cmd->add_option("--out", opts->out, "Submission JSON to write (with --frames: an OpenLane-V2 results JSON)")
      ->required();
  cmd->add_option("--frames", opts->frames,
                  "An `nsgraph frames` export of --dataset: the tiles' graphs stitched and cut around each of its "
                  "--split frames, written as OpenLane-V2 results (score them with `score --frames`)");
  cmd->add_flag("--ladder", opts->ladder,
                "Also every rung of --split's observation ladder (keys <key>-r<k>) in the same submission: score it "
                "once for the per-rung report");
  add_threads_option(cmd, opts->threads);
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_predict(*opts, ctx); }; });
}

}  // namespace nsg::cli
