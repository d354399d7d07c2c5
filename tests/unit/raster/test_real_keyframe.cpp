// The real key frame (tests/data/real/scene-0061-keyframe: v1.0-mini scene-0061's first
// sample, real LIDAR_TOP sweep, six real JPEGs, real calibrations; issue 19). The LiDAR and
// RGB layers are checked against the devkit chain written out here independently: every
// kept point projected into each camera as `map_pointcloud_to_image` does (lidar → ego →
// global → camera ego → camera, depth > 1 m, 1 < u < W − 1, 1 < v < H − 1), colours sampled
// bilinearly from the full-resolution JPEG.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "test_support.h"

namespace nsg::raster {
namespace {

using nuscenes::Database;
using nuscenes::Index;

constexpr double kNearM = 38.0;  // the radius around the ego

std::filesystem::path real_root() { return test::data_dir() / "real/scene-0061-keyframe"; }

// One camera as the devkit sees it: global → camera-ego → camera, then K.
struct DevkitCamera {
  Eigen::Matrix3d ego_rot, cam_rot, k;
  Eigen::Vector3d ego_t, cam_t;
  int width = 0, height = 0;
  std::string name;
  nuscenes::RgbImage image;  // full resolution

  // Depth and pixel of a global point (devkit view_points with normalize=True).
  bool project(const Eigen::Vector3d& global, double& depth, double& u, double& v) const {
    const Eigen::Vector3d cam = cam_rot.transpose() * (ego_rot.transpose() * (global - ego_t) - cam_t);
    depth = cam.z();
    const Eigen::Vector3d q = k * cam;
    u = q.x() / q.z();
    v = q.y() / q.z();
    return depth > 1.0 && u > 1.0 && u < width - 1.0 && v > 1.0 && v < height - 1.0;
  }
  std::array<double, 3> bilinear(double u, double v) const {
    const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
    const double fx = u - x0, fy = v - y0;
    std::array<double, 3> out{};
    for (int c = 0; c < 3; ++c)
      out[c] = (image.at(x0, y0)[c] * (1 - fx) + image.at(x0 + 1, y0)[c] * fx) * (1 - fy) +
               (image.at(x0, y0 + 1)[c] * (1 - fx) + image.at(x0 + 1, y0 + 1)[c] * fx) * fy;
    return out;
  }
};

std::vector<DevkitCamera> devkit_cameras(const Database& db) {
  std::vector<DevkitCamera> cams;
  nuscenes::JpegDecoder decoder;
  for (const nuscenes::SampleData& sd : db.sample_data) {
    if (sd.modality != nuscenes::Modality::kCamera || !sd.is_key_frame) continue;
    const auto& cs = db.calibrated_sensor[sd.calibrated_sensor];
    const auto& ego = db.ego_pose[sd.ego_pose];
    DevkitCamera c;
    c.ego_rot = geometry::rotation_matrix(ego.rotation);
    c.cam_rot = geometry::rotation_matrix(cs.rotation);
    c.ego_t = Eigen::Vector3d(ego.translation[0], ego.translation[1], ego.translation[2]);
    c.cam_t = Eigen::Vector3d(cs.translation[0], cs.translation[1], cs.translation[2]);
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) c.k(r, k) = (*cs.camera_intrinsic)[r][k];
    c.name = db.channel(sd);
    c.width = sd.width;
    c.height = sd.height;
    c.image = decoder.decode_file(db.file_path(sd));
    cams.push_back(std::move(c));
  }
  return cams;
}

class RealKeyFrame : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    db_ = new Database(Database::load(real_root(), "v1.0-mini"));
    RasterOptions options;
    layers_ = new LocationLayers(accumulate_location(*db_, "singapore-onenorth", options, 1));
    CameraOptions camera = options.camera;
    camera.semantic = false;  // the real release has no class masks
    colors_ = new ColorLayer(colorize_location(*db_, "singapore-onenorth", layers_->lidar, {}, camera, 1));
    const Index lidar = db_->key_frame(0, "LIDAR_TOP");
    const auto& ego = db_->ego_pose[db_->sample_data[lidar].ego_pose];
    ego_x_ = ego.translation[0];
    ego_y_ = ego.translation[1];
  }
  static void TearDownTestSuite() {
    delete colors_;
    delete layers_;
    delete db_;
  }
  static inline Database* db_ = nullptr;
  static inline LocationLayers* layers_ = nullptr;
  static inline ColorLayer* colors_ = nullptr;
  static inline double ego_x_ = 0.0, ego_y_ = 0.0;
};

// The LiDAR layer holds the cells of the devkit chain: LidarPointCloud.from_file,
// remove_close(1.0), the sensor → ego → global transform, binned at 0.2 m.
TEST_F(RealKeyFrame, LidarCellsAreTheDevkitChainsCells) {
  const Index lidar = db_->key_frame(0, "LIDAR_TOP");
  std::vector<nuscenes::LidarPoint> points = nuscenes::read_lidar_points(db_->file_path(db_->sample_data[lidar]));
  ASSERT_EQ(points.size(), 34688u);  // real-data.md
  const double max_range = RasterOptions{}.lidar.max_range_m;
  std::erase_if(points, [&](const nuscenes::LidarPoint& p) {
    return (std::abs(p.x) < 1.0f && std::abs(p.y) < 1.0f) || std::hypot(p.x, p.y) > max_range;
  });
  nuscenes::sensor_to_global(*db_, lidar, points);
  std::set<std::pair<int64_t, int64_t>> cells;
  for (const auto& p : points)
    cells.insert({static_cast<int64_t>(std::floor(p.x / 0.2)), static_cast<int64_t>(std::floor(p.y / 0.2))});
  std::printf("[ figures ] real key frame: %zu LiDAR cells (devkit chain %zu)\n", layers_->stats.covered_cells,
              cells.size());
  EXPECT_EQ(layers_->stats.covered_cells, cells.size());
  size_t found = 0;
  for (const auto& [col, row] : cells) {
    const LidarCell* c = layers_->lidar.cells().find({col, row});
    found += c != nullptr && c->has_data();
  }
  EXPECT_EQ(found, cells.size());
}

// Issue 19: at least 85 % of the LiDAR cells within 38 m that some camera sees get a
// colour, and the colours are the devkit projection's (median difference ≤ 2 levels).
TEST_F(RealKeyFrame, RgbColoursWhatTheCamerasSee) {
  const std::vector<DevkitCamera> cams = devkit_cameras(*db_);
  ASSERT_EQ(cams.size(), 6u);
  size_t seen = 0, coloured_seen = 0;
  std::array<size_t, 4> ring_cells{}, ring_coloured{};  // 0–10, 10–20, 20–30, 30–40 m
  std::vector<double> diffs;
  layers_->lidar.cells().for_each([&](CellIndex c, const LidarCell& cell) {
    if (!cell.has_data()) return;
    const double dist = std::hypot(cell.x - ego_x_, cell.y - ego_y_);
    const ColorCell* cc = colors_->cells().find(c);
    const bool coloured = cc != nullptr && (cc->flags & kCoverageRgb);
    if (dist < 40.0) {
      ++ring_cells[static_cast<size_t>(dist / 10.0)];
      ring_coloured[static_cast<size_t>(dist / 10.0)] += coloured;
    }
    if (dist > kNearM) return;
    // The closest camera that sees the point, as the devkit would project it.
    const DevkitCamera* best = nullptr;
    double best_depth = 0.0, best_u = 0.0, best_v = 0.0;
    for (const DevkitCamera& cam : cams) {
      double depth, u, v;
      if (!cam.project(Eigen::Vector3d(cell.x, cell.y, cell.z), depth, u, v)) continue;
      if (best != nullptr && !(depth < best_depth)) continue;
      best = &cam;
      best_depth = depth, best_u = u, best_v = v;
    }
    if (best == nullptr) return;
    ++seen;
    if (!coloured) return;
    ++coloured_seen;
    const std::array<double, 3> ref = best->bilinear(best_u, best_v);
    diffs.push_back((std::abs(cc->r - ref[0]) + std::abs(cc->g - ref[1]) + std::abs(cc->b - ref[2])) / 3.0);
  });
  ASSERT_FALSE(diffs.empty());
  std::nth_element(diffs.begin(), diffs.begin() + diffs.size() / 2, diffs.end());
  const double median = diffs[diffs.size() / 2];
  std::printf("[ figures ] real key frame: %zu of %zu cells within %.0f m that a camera sees are coloured (%.1f %%); "
              "median colour difference %.2f levels; %zu occluded views\n",
              coloured_seen, seen, kNearM, 100.0 * coloured_seen / seen, median, colors_->stats().occluded_views);
  for (size_t r = 0; r < 4; ++r)
    std::printf("[ figures ]   %2zu–%2zu m: %zu of %zu LiDAR cells coloured (%.1f %%)\n", r * 10, r * 10 + 10,
                ring_coloured[r], ring_cells[r], ring_cells[r] ? 100.0 * ring_coloured[r] / ring_cells[r] : 0.0);
  EXPECT_GT(seen, 6000u);  // 6 811 in the devkit count
  EXPECT_GE(static_cast<double>(coloured_seen), 0.85 * static_cast<double>(seen));
  EXPECT_LE(median, 2.0);
}

// The same frame through the CLI, as a user would look at it: `inspect layers --png` writes
// the five GeoTIFFs and the LiDAR/RGB picture, and reports the cell counts of the layers.
TEST_F(RealKeyFrame, InspectLayersOnTheRealKeyFrame) {
  test::TempDir out("real_inspect_layers");
  const std::string png = (out.path() / "panels.png").string();
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "layers", "--dataroot", real_root().string(), "--version", "v1.0-mini", "--location",
                         "singapore-onenorth", "--out", out.path().string(), "--no-semantic", "--png", png});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["sweeps"], 1);
  EXPECT_EQ(j["cells"]["lidar"], layers_->stats.covered_cells);  // 8 975: the devkit chain's cells
  EXPECT_EQ(j["cells"]["rgb"], colors_->rgb_cells());
  EXPECT_GT(j["cells"]["rgb"].get<size_t>(), 6000u);  // 3 283 before the occlusion fix (issue 19)
  EXPECT_EQ(j["cells"]["semantic"], 0);
  for (const char* layer : {"lidar", "rgb", "semantic", "vehicle", "coverage"})
    EXPECT_TRUE(std::filesystem::exists(out.path() / (std::string("singapore-onenorth.") + layer + ".tif"))) << layer;
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 10'000u);
}

}  // namespace
}  // namespace nsg::raster
