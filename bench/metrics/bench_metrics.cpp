// Scoring throughput on typical tiles: lane-like graphs of ~100-300 nodes (a road with
// two lanes each way plus a crossing road, nodes every 2 m), one core. Target >= 100
// tiles/s (issue 8). items_per_second = tiles/s.
#include <benchmark/benchmark.h>

#include <cmath>

#include "nsg/core/rng.h"
#include "nsg/metrics/measure.h"

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

}  // namespace

BENCHMARK_MAIN();
