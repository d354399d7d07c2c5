// Scoring throughput on typical tiles: lane-like graphs of ~100-300 nodes (a road with
// two lanes each way plus a crossing road, nodes every 2 m), one core. Target >= 100
// tiles/s. items_per_second = tiles/s. BM_ScoreSubmission is the end-to-end
// rate of `nsgraph score`'s work: reading a 200-tile submission file within the validate
// limits, parsing it, measuring every tile and finalizing the aggregate.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "nsg/core/atomic_file.h"
#include "nsg/core/rng.h"
#include "nsg/metrics/io.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/score.h"

namespace {

using nsg::metrics::Graph;

// Adds a straight lane from (u0, v0) to (u1, v1) with nodes every `spacing_px`.
void add_lane(Graph& g, double u0, double v0, double u1, double v1, double spacing_px) {
  const double len = std::hypot(u1 - u0, v1 - v0);
  const int pieces = std::max(1, static_cast<int>(std::ceil(len / spacing_px)));
  const auto first = static_cast<int64_t>(g.nodes.size());
  for (int k = 0; k <= pieces; ++k) {
    const double t = static_cast<double>(k) / pieces;
    g.nodes.push_back({u0 + t * (u1 - u0), v0 + t * (v1 - v0)});
  }
  for (int64_t k = 0; k < pieces; ++k) g.edges.push_back({first + k, first + k + 1});
}

// `lanes_per_direction` lanes each way on a horizontal road and a vertical one.
Graph road_tile(int lanes_per_direction) {
  Graph g;
  const double width_px = 17.5, spacing_px = 10.0;  // 3.5 m lanes, 2 m node spacing
  for (int k = 0; k < lanes_per_direction; ++k) {
    const double off = width_px * (k + 0.5);
    add_lane(g, -0.5, 128 - off, 255.5, 128 - off, spacing_px);
    add_lane(g, 255.5, 128 + off, -0.5, 128 + off, spacing_px);
    add_lane(g, 128 + off, -0.5, 128 + off, 255.5, spacing_px);
    add_lane(g, 128 - off, 255.5, 128 - off, -0.5, spacing_px);
  }
  return g;
}

Graph jitter(const Graph& g, double sigma_px, uint64_t seed) {
  nsg::Rng rng(seed);
  Graph out = g;
  for (auto& n : out.nodes) {
    n.u += sigma_px * rng.normal();
    n.v += sigma_px * rng.normal();
  }
  return out;
}

void BM_MeasureTile(benchmark::State& state) {
  const Graph gt = road_tile(static_cast<int>(state.range(0)));
  const Graph pred = jitter(gt, 1.0, 7);
  const nsg::metrics::MetricParams params;
  for (auto _ : state) {
    nsg::metrics::TileMeasurement t = nsg::metrics::measure("k", gt, &pred, params);
    benchmark::DoNotOptimize(t);
  }
  state.counters["nodes"] = static_cast<double>(gt.nodes.size());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_MeasureTile)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

nlohmann::json submission_tile(const Graph& g) {
  nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
  for (const auto& n : g.nodes) nodes.push_back({n.u, n.v});
  for (const auto& [i, j] : g.edges) edges.push_back({i, j});
  return {{"nodes", nodes}, {"edges", edges}};
}

// 200 tiles of 1-3 lanes each way (~108-324 nodes), predictions jittered by 1 px.
void BM_ScoreSubmission(benchmark::State& state) {
  constexpr int kTiles = 200;
  nsg::metrics::GraphSet gt;
  nlohmann::json tiles = nlohmann::json::object();
  for (int k = 0; k < kTiles; ++k) {
    const std::string key = "bench-" + std::to_string(1000000 + k).substr(1);
    gt[key] = road_tile(1 + k % 3);
    tiles[key] = submission_tile(jitter(gt[key], 1.0, static_cast<uint64_t>(k)));
  }
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("nsg-bench-submission-" + std::to_string(getpid()) + ".json");
  nsg::write_file_atomic(file, nlohmann::json{{"schema_version", "1"}, {"tiles", tiles}}.dump());
  nsg::metrics::ScoreOptions options;  // one thread
  for (auto _ : state) {
    nsg::Issues issues;
    const auto doc = nsg::metrics::read_submission_file(file, {}, issues);
    if (!doc) state.SkipWithError(issues.format().c_str());
    const nsg::metrics::GraphSet pred = nsg::metrics::graphs_from_submission(*doc, file.string());
    nsg::metrics::ScoreReport report = nsg::metrics::score(gt, pred, options);
    benchmark::DoNotOptimize(report);
  }
  std::filesystem::remove(file);
  state.SetItemsProcessed(state.iterations() * kTiles);
}
BENCHMARK(BM_ScoreSubmission)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
