// `nsgraph predict`: the reference model's lane graphs for a dataset split, as a
// submission (schemas/v1/submission.schema.json). A model ending in .onnx is LaneGraphNet
// exported by `python -m nsgraph.models.export`, run through OpenCV dnn (lib/model onnx_net).
#include <chrono>
#include <memory>
#include <optional>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/io.h"
#include "nsg/model/model.h"
#include "nsg/model/onnx_net.h"

namespace nsg::cli {
namespace {

struct PredictCliOptions {
  std::string model;
  std::string dataset;
  std::string split = "test";
  std::string out;
  int threads = 0;

  void validate() const {
    NSG_CHECK(!out.empty(), ConfigError, "", "--out", "a submission file to write");
    NSG_CHECK(threads >= 0, ConfigError, "", "--threads", "≥ 0 (0 = all cores)");
  }
};

bool is_onnx(const std::string& path) { return ends_with(path, ".onnx"); }

int run_predict(const PredictCliOptions& o, const Context& ctx) {
  o.validate();
  std::optional<model::LaneModel> forest;
  if (!is_onnx(o.model)) forest = model::LaneModel::load(o.model);
  const io::Dataset dataset = io::Dataset::open(o.dataset);
  const auto t0 = std::chrono::steady_clock::now();
  const metrics::GraphSet graphs = forest
                                       ? model::predict_dataset(*forest, dataset, o.split, o.threads, !ctx.quiet)
                                       : model::predict_dataset_onnx(o.model, dataset, o.split, o.threads, !ctx.quiet);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  metrics::write_submission(graphs, o.out);
  size_t nodes = 0, edges = 0;
  for (const auto& [key, g] : graphs) {
    nodes += g.nodes.size();
    edges += g.edges.size();
  }
  log::info(
      strprintf("predicted %zu tiles of '%s' with the %s model in %.1f s (%.1f tiles/s): %zu nodes, "
                "%zu edges → %s",
                graphs.size(), o.split.c_str(),
                forest ? model::to_string(forest->options().variant).c_str() : "LaneGraphNet (ONNX)", s,
                graphs.size() / std::max(s, 1e-9), nodes, edges, o.out.c_str()));
  return kExitOk;
}

}  // namespace

void add_predict_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<PredictCliOptions>();
  CLI::App* cmd = parent.add_subcommand("predict", "Predict lane graphs for a dataset split with a trained model");
  cmd->add_option("--model", opts->model,
                  "Model file from `nsgraph train`, or LaneGraphNet's M.onnx (M.pairs.onnx next to it)")
      ->required();
  cmd->add_option("--dataset", opts->dataset, "Dataset folder (manifest.json)")->required();
  cmd->add_option("--split", opts->split, "Split to predict")->capture_default_str();
  cmd->add_option("--out", opts->out, "Submission JSON to write")->required();
  cmd->add_option("--threads", opts->threads, "Worker threads (0 = all cores; results do not depend on it)")
      ->capture_default_str();
  cmd->callback([opts, &ctx]() { ctx.run = [opts, &ctx]() { return run_predict(*opts, ctx); }; });
}

}  // namespace nsg::cli
