// Scoring (metrics::score_submission, the CLI's sequence) and the submission writer
// (metrics::write_submission) for nsgraph.score / score_tile / write_submission.
#include <filesystem>
#include <optional>

#include "bindings.h"
#include "convert.h"
#include "nsg/core/error.h"
#include "nsg/core/json.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/score.h"
#include "nsg/metrics/score_submission.h"
#include "nsg/metrics/submission_input.h"

namespace nsg::py_bind {
namespace {

namespace fs = std::filesystem;

// A submission-format document given as a path or as JSON text; checked like `nsgraph
// score` checks its --submission.
metrics::CheckedSubmission checked_submission(const std::string& source, bool is_path, const std::string& label,
                                              const std::string& schemas_dir) {
  if (is_path) return metrics::check_submission_file(source, schemas_dir);
  return metrics::check_submission_text(source, label, schemas_dir);
}

metrics::Graph graph_arg(const Points& nodes, const Pairs& edges, const std::string& what) {
  metrics::Graph g;
  for (const auto& p : points_arg(nodes, what + " nodes")) g.nodes.push_back({p[0], p[1]});
  g.edges = pairs_arg(edges, what + " edges");
  return g;
}

metrics::ScoreOptions score_options(const std::string& params_json, int threads) {
  metrics::ScoreOptions o;
  o.params = metrics::MetricParams::from_json(parse_json(params_json, "score parameters"), "score parameters");
  o.params.validate();
  o.threads = threads;
  o.validate();
  return o;
}

// A source as nsgraph.score passes it: a path, or submission-format JSON text.
metrics::ScoreSource score_source(const std::string& source, bool is_path, const std::string& label) {
  if (is_path) return {source, std::nullopt, label};
  return metrics::ScoreSource::memory(source, label);
}

// (report dict, []) or (None, issues) when the submission has problems (the CLI's exit 1).
py::tuple score(const std::string& gt, bool gt_is_path, const std::string& sub, bool sub_is_path,
                const std::string& split, const std::string& params_json, int threads, const std::string& schemas_dir,
                const std::string& gt_label, const std::string& sub_label, bool verify, double max_seconds) {
  metrics::SubmissionScoreOptions options;
  options.verify_ground_truth = verify;
  options.score = score_options(params_json, threads);
  options.score.max_seconds = max_seconds;
  options.score.validate();
  options.split = split;
  options.schemas_dir = schemas_dir;
  metrics::ScoredSubmission scored;
  {
    py::gil_scoped_release release;
    scored = metrics::score_submission(score_source(gt, gt_is_path, gt_label),
                                       score_source(sub, sub_is_path, sub_label), options);
  }
  if (!scored.scored())
    return py::make_tuple(py::none(), issues_to_py(scored.issues), printable_utf8(scored.issues.format()));
  return py::make_tuple(json_to_py(metrics::report_to_json(scored.report)), py::list(), "");
}

// (measurement dict, []) or (None, issues, text) when the prediction has problems a file's
// tile would have (NaN, an index out of range, beyond the limits); a ground truth with
// such problems throws DataError.
// gt_edge_flags: metrics::EdgeFlag bits per ground-truth edge (the per-class recalls), or
// empty when the ground truth has no edge attributes.
// A ground-truth graph (the map, or a map-update tile's prior map) with its EdgeFlag bytes,
// checked as a file's graph would be; DataError naming `what` otherwise.
metrics::Graph map_arg(const Points& nodes, const Pairs& edges, const std::vector<uint8_t>& flags,
                       const std::string& key, const std::string& what) {
  metrics::Graph g = graph_arg(nodes, edges, what);
  NSG_CHECK(flags.empty() || flags.size() == g.edges.size(), DataError, what, key + "/edge_flags",
            "one edge class flag per edge");
  g.edge_flags = flags;
  const Issues issues = metrics::check_graph(g, key, what);
  NSG_CHECK(issues.empty(), DataError, what, key, "a graph a file could hold:\n" + issues.format());
  return g;
}

py::tuple score_tile(const Points& gt_nodes, const Pairs& gt_edges, const std::vector<uint8_t>& gt_edge_flags,
                     std::optional<Points> pred_nodes, std::optional<Pairs> pred_edges, const std::string& params_json,
                     const std::string& key, std::optional<Points> prior_nodes, std::optional<Pairs> prior_edges,
                     const std::vector<uint8_t>& prior_edge_flags) {
  const metrics::ScoreOptions options = score_options(params_json, 1);
  metrics::Graph gt = map_arg(gt_nodes, gt_edges, gt_edge_flags, key, "ground truth");
  if (prior_nodes)
    gt.prior = std::make_shared<const metrics::Graph>(
        map_arg(*prior_nodes, prior_edges ? *prior_edges : Pairs(), prior_edge_flags, key, "prior ground truth"));
  std::optional<metrics::Graph> pred;
  if (pred_nodes) {
    pred = graph_arg(*pred_nodes, pred_edges ? *pred_edges : Pairs(), "prediction");
    const Issues issues = metrics::check_graph(*pred, key, "prediction");
    if (!issues.empty()) return py::make_tuple(py::none(), issues_to_py(issues), printable_utf8(issues.format()));
  }
  metrics::TileMeasurement m;
  Issues work_issues;
  {
    py::gil_scoped_release release;
    try {
      m = metrics::measure(key, gt, pred ? &*pred : nullptr, options.params);
    } catch (const metrics::SearchWorkExceeded& e) {
      work_issues.error("submission.size", e.record(), e.expected());
    }
  }
  if (!work_issues.empty())
    return py::make_tuple(py::none(), issues_to_py(work_issues), printable_utf8(work_issues.format()));
  return py::make_tuple(json_to_py(metrics::measurement_to_json(m)), py::list(), "");
}

// Writes with the writer `nsgraph predict` uses, then checks the file like `nsgraph score`
// would; a file with problems is removed and the issues returned.
py::tuple write_submission(const std::string& path, const std::vector<std::string>& keys,
                           const std::vector<Points>& nodes, const std::vector<Pairs>& edges,
                           const std::string& schemas_dir) {
  NSG_CHECK(keys.size() == nodes.size() && keys.size() == edges.size(), InternalError, path, "",
            "as many node and edge arrays as keys");
  metrics::GraphSet graphs;
  for (size_t k = 0; k < keys.size(); ++k) {
    metrics::Graph g;
    for (const auto& p : points_arg(nodes[k], "tile '" + keys[k] + "' nodes")) g.nodes.push_back({p[0], p[1]});
    g.edges = pairs_arg(edges[k], "tile '" + keys[k] + "' edges");
    NSG_CHECK(graphs.emplace(keys[k], std::move(g)).second, ConfigError, path, keys[k], "each tile key once");
  }
  Issues issues;
  {
    py::gil_scoped_release release;
    metrics::write_submission(graphs, path);
    issues = metrics::check_submission_file(path, schemas_dir).issues;
    if (!issues.empty()) fs::remove(path);
  }
  return py::make_tuple(issues_to_py(issues), printable_utf8(issues.format()));
}

py::tuple check_submission(const std::string& source, bool is_path, const std::string& label,
                           const std::string& schemas_dir) {
  Issues issues;
  {
    py::gil_scoped_release release;
    issues = checked_submission(source, is_path, label, schemas_dir).issues;
  }
  return py::make_tuple(issues_to_py(issues), printable_utf8(issues.format()));
}

}  // namespace

void bind_metrics(py::module_& m) {
  m.def("score", &score, py::arg("ground_truth"), py::arg("ground_truth_is_path"), py::arg("submission"),
        py::arg("submission_is_path"), py::arg("split"), py::arg("params_json"), py::arg("threads"),
        py::arg("schemas_dir"), py::arg("ground_truth_label"), py::arg("submission_label"), py::arg("verify") = true,
        py::arg("max_seconds") = metrics::ScoreOptions{}.max_seconds);
  m.def("score_tile", &score_tile, py::arg("gt_nodes"), py::arg("gt_edges"), py::arg("gt_edge_flags"),
        py::arg("pred_nodes"), py::arg("pred_edges"), py::arg("params_json"), py::arg("key"),
        py::arg("prior_nodes") = py::none(), py::arg("prior_edges") = py::none(),
        py::arg("prior_edge_flags") = std::vector<uint8_t>());
  // The scorer's EdgeFlag bits by the graph.json attribute or change label they stand for.
  py::dict flags;
  flags["connector"] = static_cast<int>(metrics::kEdgeConnector);
  flags["in_intersection"] = static_cast<int>(metrics::kEdgeInIntersection);
  flags["unchanged"] = static_cast<int>(metrics::kEdgeUnchanged);
  flags["added"] = static_cast<int>(metrics::kEdgeAdded);
  flags["removed"] = static_cast<int>(metrics::kEdgeRemoved);
  flags["moved"] = static_cast<int>(metrics::kEdgeMoved);
  flags["retyped"] = static_cast<int>(metrics::kEdgeRetyped);
  m.attr("EDGE_FLAGS") = flags;
  m.def("write_submission", &write_submission, py::arg("path"), py::arg("keys"), py::arg("nodes"), py::arg("edges"),
        py::arg("schemas_dir"));
  m.def("check_submission", &check_submission, py::arg("source"), py::arg("is_path"), py::arg("label"),
        py::arg("schemas_dir"));
  m.def("default_params_json", [] { return metrics::MetricParams{}.to_json().dump(); });
  // The metric table (metrics::metric_info) and the headline metrics, as the C++ declares them.
  py::tuple table(static_cast<size_t>(metrics::kMetricCount));
  for (int k = 0; k < metrics::kMetricCount; ++k) {
    const metrics::MetricInfo& info = metrics::metric_info(k);
    py::dict d;
    d["name"] = info.name;
    d["unit"] = info.unit;
    d["lower_is_better"] = info.lower_is_better;
    d["leaderboard"] = info.leaderboard;
    d["description"] = info.description;
    table[static_cast<size_t>(k)] = d;
  }
  m.attr("METRICS") = table;
  py::list headline;
  for (const metrics::HeadlineMetric& h : metrics::headline_metrics()) headline.append(metrics::metric_name(h.metric));
  m.attr("HEADLINE_METRICS") = py::tuple(headline);
}

}  // namespace nsg::py_bind
