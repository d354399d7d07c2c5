// Raster-stage throughput, one core (docs/benchmarks.md target ≥ 3 000 sweeps/s per core
// from page cache):
//  - BM_AccumulateLocation: accumulate_location (read .pcd.bin from page cache, roof/range
//    filter, devkit sensor → ego → global, lowest-z binning) on a synthetic release
//    (samples/synth/tiny.json with real-size sweeps: 34 720 points, 32 beams), generated
//    once into a temp dir. items_per_second = sweeps/s.
//  - BM_ColorizeLocation: colorize_location on the same release, per JPEG scale;
//    items_per_second = key-frame camera images/s.
//  - BM_AddPoints: the lowest-z binning alone on in-memory real-size sweeps.
//  - BM_AddSweep/{0,1}: filter + both transforms + binning (LidarLayer::add_sweep) on
//    in-memory real-size sensor-frame sweeps; 0 = portable column path, 1 = fused AVX2 kernel.
//  - BM_AccumulateRelease: accumulate_location on the release at $NSG_BENCH_DATAROOT
//    ($NSG_BENCH_VERSION, default v1.0-mini; every location), when set; sweeps/s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>
#include "nsg/core/rng.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/synth/config.h"
#include "nsg/synth/release.h"

namespace {

namespace fs = std::filesystem;
using nsg::nuscenes::LidarPoint;

constexpr int kBeams = 32, kPointsPerSweep = 34720, kSweeps = 40;

// A real-size sweep in the sensor frame: 32 beams from −30.67° to +10.67°, 1085 firings
// per turn; downward beams hit flat ground 1.84 m below, upward ones a façade 15–40 m away.
std::vector<LidarPoint> synthetic_sweep(nsg::Rng& rng) {
  std::vector<LidarPoint> pts;
  pts.reserve(kPointsPerSweep);
  const int firings = kPointsPerSweep / kBeams;
  for (int f = 0; f < firings; ++f) {
    const double az = 2 * std::numbers::pi * f / firings;
    const double wall_m = 15.0 + 25.0 * (0.5 + 0.5 * std::sin(3 * az));
    for (int b = 0; b < kBeams; ++b) {
      const double el = (-30.67 + 41.34 * b / (kBeams - 1)) * std::numbers::pi / 180;
      double range = el < -0.01 ? 1.84 / std::tan(-el) : wall_m / std::cos(el);
      range = std::min(range, wall_m / std::cos(el)) * (1.0 + 0.001 * rng.uniform(-1.0, 1.0));
      pts.push_back({static_cast<float>(range * std::cos(el) * std::cos(az)),
                     static_cast<float>(range * std::cos(el) * std::sin(az)), static_cast<float>(range * std::sin(el)),
                     static_cast<float>(rng.uniform(0.0, 100.0)), static_cast<float>(b)});
    }
  }
  return pts;
}

// Sensor → ego (LIDAR_TOP-like) and ego → global: driving east 0.4 m per sweep (8 m/s, 20 Hz).
nsg::geometry::Rigid3 ego_from_sensor() {
  return nsg::geometry::Rigid3::from_pose({0.94, 0.0, 1.84}, nsg::geometry::quaternion_from_yaw(-std::numbers::pi / 2));
}
nsg::geometry::Rigid3 global_from_ego(int k) {
  return nsg::geometry::Rigid3::from_pose({400.0 + 0.4 * k, 1100.0, 0.0}, nsg::geometry::quaternion_from_yaw(0.01 * k));
}

void BM_AddPoints(benchmark::State& state) {
  nsg::Rng rng(11);
  std::vector<std::vector<LidarPoint>> sweeps;
  for (int k = 0; k < kSweeps; ++k) {
    sweeps.push_back(synthetic_sweep(rng));
    float* xyz = reinterpret_cast<float*>(sweeps.back().data());
    nsg::geometry::transform_points_devkit(ego_from_sensor(), xyz, sweeps.back().size(), 5);
    nsg::geometry::transform_points_devkit(global_from_ego(k), xyz, sweeps.back().size(), 5);
  }
  nsg::raster::LidarLayer layer;
  size_t k = 0;
  for (auto _ : state) {
    const std::vector<LidarPoint>& s = sweeps[k % sweeps.size()];
    layer.add_points(reinterpret_cast<const float*>(s.data()), s.size(), 5, static_cast<int32_t>(k));
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["points_per_sweep"] = kPointsPerSweep;
}
BENCHMARK(BM_AddPoints)->Unit(benchmark::kMicrosecond);

void BM_AddSweep(benchmark::State& state) {
  using Path = nsg::raster::LidarLayer::SweepPath;
  const Path path = state.range(0) == 0 ? Path::kPortable : Path::kFused;
  if (path == Path::kFused && !nsg::raster::LidarLayer::fused_kernel_available()) {
    state.SkipWithError("no AVX2");
    return;
  }
  nsg::Rng rng(11);
  std::vector<std::vector<LidarPoint>> sweeps;
  for (int k = 0; k < kSweeps; ++k) sweeps.push_back(synthetic_sweep(rng));
  nsg::raster::LidarLayer layer;
  const nsg::raster::LidarOptions options;
  size_t k = 0, kept = 0;
  for (auto _ : state) {
    const std::vector<LidarPoint>& s = sweeps[k % sweeps.size()];
    kept +=
        layer.add_sweep(reinterpret_cast<const float*>(s.data()), s.size(), 0, ego_from_sensor(),
                        global_from_ego(static_cast<int>(k % sweeps.size())), options, static_cast<int32_t>(k), path);
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["kept_per_sweep"] = static_cast<double>(kept) / static_cast<double>(std::max<size_t>(k, 1));
}
BENCHMARK(BM_AddSweep)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// accumulate_location over every location of an existing release (the bench release of
// `make bench`), page cache warm after the first iteration.
void BM_AccumulateRelease(benchmark::State& state) {
  const char* root = std::getenv("NSG_BENCH_DATAROOT");
  if (root == nullptr) {
    state.SkipWithError("NSG_BENCH_DATAROOT not set");
    return;
  }
  const char* version = std::getenv("NSG_BENCH_VERSION");
  const nsg::nuscenes::Database db = nsg::nuscenes::Database::load(root, version ? version : "v1.0-mini");
  std::vector<std::string> locations;
  for (size_t i = 0; i < db.log.size(); ++i)
    if (std::find(locations.begin(), locations.end(), db.log[i].location) == locations.end())
      locations.push_back(db.log[i].location);
  size_t sweeps = 0;
  for (auto _ : state)
    for (const std::string& location : locations)
      sweeps += nsg::raster::accumulate_location(db, location, nsg::raster::RasterOptions{}, 1).stats.sweeps;
  state.SetItemsProcessed(static_cast<int64_t>(sweeps));
}
BENCHMARK(BM_AccumulateRelease)->Unit(benchmark::kMillisecond);

// Peak resident memory of the process so far (Linux ru_maxrss is in KiB).
double peak_rss_mb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// The tiny synthetic city with real-size sweeps, generated once.
struct Release {
  fs::path dir = fs::temp_directory_path() / ("nsg_bench_raster_release_" + std::to_string(::getpid()));
  nsg::synth::SynthConfig config;
  std::unique_ptr<nsg::nuscenes::Database> db;
  Release() {
    config = nsg::synth::SynthConfig::from_file(fs::path(NSG_SOURCE_DIR) / "samples/synth/tiny.json");
    config.lidar.points_per_sweep = kPointsPerSweep;
    config.lidar.roof_points = 8000;
    nsg::synth::SynthRunOptions run;
    run.out_dir = dir;
    run.progress = false;
    nsg::synth::write_release(config, run);
    db = std::make_unique<nsg::nuscenes::Database>(nsg::nuscenes::Database::load(dir, config.version));
  }
  ~Release() { fs::remove_all(dir); }
};

const Release& release() {
  static const Release r;
  return r;
}

void BM_AccumulateLocation(benchmark::State& state) {
  const Release& r = release();
  size_t sweeps = 0;
  for (auto _ : state) {
    const nsg::raster::LocationLayers layers =
        nsg::raster::accumulate_location(*r.db, r.config.location, nsg::raster::RasterOptions{}, 1);
    sweeps += layers.stats.sweeps;
  }
  state.SetItemsProcessed(static_cast<int64_t>(sweeps));
  state.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(BM_AccumulateLocation)->Unit(benchmark::kMillisecond);

void BM_ColorizeLocation(benchmark::State& state) {
  const Release& r = release();
  const nsg::raster::LocationLayers layers =
      nsg::raster::accumulate_location(*r.db, r.config.location, nsg::raster::RasterOptions{}, 1);
  nsg::raster::CameraOptions options;
  options.jpeg_scale_denom = static_cast<int>(state.range(0));
  size_t images = 0, cells = 0;
  for (auto _ : state) {
    const nsg::raster::ColorLayer colors =
        nsg::raster::colorize_location(*r.db, r.config.location, layers.lidar, {}, options, 1);
    images += colors.stats().images;
    cells = colors.rgb_cells();
  }
  state.SetItemsProcessed(static_cast<int64_t>(images));
  state.counters["rgb_cells"] = static_cast<double>(cells);
  state.counters["lidar_cells"] = static_cast<double>(layers.stats.covered_cells);
  state.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(BM_ColorizeLocation)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
