// The real key frame (tests/data/real/scene-0061-keyframe: v1.0-mini scene-0061's first
// sample, real LIDAR_TOP sweep, six real JPEGs, real calibrations). The LiDAR and RGB layers
// are checked against golden files the official nuScenes devkit computed
// (tests/data/golden/real-keyframe/), not against this library's own transforms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/nuscenes/database.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "test_support.h"

namespace nsg::raster {
namespace {

using nuscenes::Database;

constexpr double kNearM = 38.0;  // the golden camera cells' radius around the ego

std::filesystem::path real_root() { return test::data_dir() / "real/scene-0061-keyframe"; }

// The golden files: the official devkit's answers for this frame (made once by
// tests/data/golden/real-keyframe/make_golden.py, which names the devkit commit).
std::filesystem::path golden_dir() { return test::data_dir() / "golden/real-keyframe"; }

std::vector<std::string> csv_rows(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line))
    if (!line.empty()) rows.push_back(line);
  return rows;
}

// lidar-cells.csv: the devkit chain's cells with their lowest point.
struct GoldenLidarCell {
  int64_t col = 0, row = 0;
  int32_t point = 0;
  int64_t x_mm = 0, y_mm = 0, z_mm = 0;
  int intensity = 0;
};

std::vector<GoldenLidarCell> golden_lidar_cells() {
  std::vector<GoldenLidarCell> cells;
  for (const std::string& line : csv_rows(golden_dir() / "lidar-cells.csv")) {
    GoldenLidarCell c;
    long long col, row, x, y, z;
    if (std::sscanf(line.c_str(), "%lld,%lld,%d,%lld,%lld,%lld,%d", &col, &row, &c.point, &x, &y, &z, &c.intensity) !=
        7)
      ADD_FAILURE() << "bad golden row: " << line;
    c.col = col, c.row = row, c.x_mm = x, c.y_mm = y, c.z_mm = z;
    cells.push_back(c);
  }
  return cells;
}

// camera-cells.csv: the cells within 38 m that the devkit's map_pointcloud_to_image puts
// into some camera; every 16th with the colour sampled bilinearly there (r < 0: none).
struct GoldenCameraCell {
  int64_t col = 0, row = 0;
  int camera = 0;
  double u = 0, v = 0, r = -1, g = -1, b = -1;
};

std::vector<GoldenCameraCell> golden_camera_cells() {
  std::vector<GoldenCameraCell> cells;
  for (const std::string& line : csv_rows(golden_dir() / "camera-cells.csv")) {
    GoldenCameraCell c;
    long long col, row;
    if (std::sscanf(line.c_str(), "%lld,%lld,%d,%lf,%lf,%lf,%lf,%lf", &col, &row, &c.camera, &c.u, &c.v, &c.r, &c.g,
                    &c.b) != 8)
      ADD_FAILURE() << "bad golden row: " << line;
    c.col = col, c.row = row;
    cells.push_back(c);
  }
  return cells;
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
  }
  static void TearDownTestSuite() {
    delete colors_;
    delete layers_;
    delete db_;
  }
  static inline Database* db_ = nullptr;
  static inline LocationLayers* layers_ = nullptr;
  static inline ColorLayer* colors_ = nullptr;
};

// The LiDAR layer holds exactly the devkit's cells (LidarPointCloud.from_file,
// remove_close(1.0), the 60 m range, the devkit's sensor → ego → global rotations and
// translations, 0.2 m bins), each keeping the devkit's lowest point: same point of the file,
// same global position and height to the millimetre, same intensity.
TEST_F(RealKeyFrame, LidarCellsAreTheDevkitsCells) {
  const std::vector<GoldenLidarCell> golden = golden_lidar_cells();
  ASSERT_EQ(golden.size(), 8975u);  // docs/real-data.md's figure
  std::printf("[ figures ] real key frame: %zu LiDAR cells (devkit %zu)\n", layers_->stats.covered_cells,
              golden.size());
  EXPECT_EQ(layers_->stats.covered_cells, golden.size());
  size_t missing = 0, other_point = 0, moved = 0, other_intensity = 0;
  for (const GoldenLidarCell& g : golden) {
    const LidarCell* c = layers_->lidar.cells().find({g.col, g.row});
    if (c == nullptr || !c->has_data()) {
      ++missing;
      continue;
    }
    other_point += c->point != g.point;
    const auto off_mm = [](float metres, int64_t mm) { return std::abs(static_cast<double>(metres) * 1000.0 - mm); };
    moved += off_mm(c->x, g.x_mm) > 1.0 || off_mm(c->y, g.y_mm) > 1.0 || off_mm(c->z, g.z_mm) > 1.0;
    other_intensity += c->intensity != g.intensity;
  }
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(other_point, 0u);
  EXPECT_EQ(moved, 0u);
  EXPECT_EQ(other_intensity, 0u);
}

// At least 88 % of the cells within 38 m that the devkit's projection puts into some camera
// get a colour (docs/real-data.md's 6 022 of 6 812 = 88.4 %), and the colours are what the devkit's
// pixel holds (median difference ≤ 1 level over the golden sample).
TEST_F(RealKeyFrame, RgbColoursWhatTheDevkitsCamerasSee) {
  const std::vector<GoldenCameraCell> golden = golden_camera_cells();
  ASSERT_EQ(golden.size(), 6812u);
  size_t coloured = 0;
  std::vector<double> diffs;
  for (const GoldenCameraCell& g : golden) {
    const ColorCell* cc = colors_->cells().find({g.col, g.row});
    if (cc == nullptr || !(cc->flags & kCoverageRgb)) continue;
    ++coloured;
    if (g.r >= 0) diffs.push_back((std::abs(cc->r - g.r) + std::abs(cc->g - g.g) + std::abs(cc->b - g.b)) / 3.0);
  }
  ASSERT_GT(diffs.size(), 300u);
  std::sort(diffs.begin(), diffs.end());
  const double median = diffs[diffs.size() / 2];
  const double p90 = diffs[diffs.size() * 9 / 10];
  std::printf(
      "[ figures ] real key frame: %zu of %zu cells within %.0f m that a camera sees are coloured (%.1f %%); "
      "colour difference to the devkit's pixels over %zu cells: median %.2f, 90th percentile %.2f levels; "
      "%zu occluded views\n",
      coloured, golden.size(), kNearM, 100.0 * coloured / golden.size(), diffs.size(), median, p90,
      colors_->stats().occluded_views);
  EXPECT_GE(static_cast<double>(coloured), 0.88 * static_cast<double>(golden.size()));
  EXPECT_LE(median, 1.0);

  // The occlusion test takes effect here: it rejects views, and with it off (no return
  // counts as closer) more of the cells get a colour.
  EXPECT_GT(colors_->stats().occluded_views, 0u);
  CameraOptions blind = RasterOptions{}.camera;
  blind.semantic = false;
  blind.occlusion_margin_m = 1e6;
  const ColorLayer unoccluded = colorize_location(*db_, "singapore-onenorth", layers_->lidar, {}, blind, 1);
  size_t coloured_blind = 0;
  for (const GoldenCameraCell& g : golden) {
    const ColorCell* cc = unoccluded.cells().find({g.col, g.row});
    coloured_blind += cc != nullptr && (cc->flags & kCoverageRgb);
  }
  std::printf("[ figures ] real key frame, occlusion test off: %zu of %zu coloured\n", coloured_blind, golden.size());
  EXPECT_EQ(unoccluded.stats().occluded_views, 0u);
  EXPECT_GT(coloured_blind, coloured);
}

// The same frame through the CLI, as a user would look at it, with the command of docs/usage.md
// and the default config (a real release has no masks and this one no lidarseg:
// camera.semantic_source auto leaves the semantic layer out and says so; it exited 2):
// `inspect layers --png` writes the five GeoTIFFs and the LiDAR/RGB picture, and reports
// the cell counts of the layers; export-cloud writes the frame's cloud.
TEST_F(RealKeyFrame, InspectLayersOnTheRealKeyFrame) {
  test::TempDir out("real_inspect_layers");
  const std::string png = (out.path() / "panels.png").string();
  const test::CommandResult r =
      test::run_nsgraph({"inspect", "layers", "--dataroot", real_root().string(), "--version", "v1.0-mini",
                         "--location", "singapore-onenorth", "--out", out.path().string(), "--png", png});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("camera.semantic_source auto: no semantic layer"), std::string::npos) << r.err;
  const test::CommandResult cloud =
      test::run_nsgraph({"export-cloud", "--dataroot", real_root().string(), "--version", "v1.0-mini", "--scene",
                         "scene-0061", "--out", (out.path() / "scene-0061.pcd").string()});
  ASSERT_EQ(cloud.exit_code, 0) << cloud.err;
  EXPECT_GT(nlohmann::json::parse(cloud.out)["points"].get<size_t>(), 8000u);
  // Every file a generate run would open is there, found by the check before any stage.
  const test::CommandResult inputs =
      test::run_nsgraph({"generate", "--dataroot", real_root().string(), "--version", "v1.0-mini", "--check-inputs"});
  ASSERT_EQ(inputs.exit_code, 0) << inputs.err;
  EXPECT_NE(inputs.err.find("inputs present: 1 scene(s), 1 map expansion(s), 1 sweep(s), 6 camera image(s), 0 mask(s)"),
            std::string::npos)
      << inputs.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["sweeps"], 1);
  EXPECT_EQ(j["cells"]["lidar"], layers_->stats.covered_cells);  // 8 975: the devkit chain's cells
  EXPECT_EQ(j["cells"]["rgb"], colors_->rgb_cells());
  EXPECT_GT(j["cells"]["rgb"].get<size_t>(), 6000u);  // 3 283 before the occlusion test was rebuilt
  EXPECT_EQ(j["cells"]["semantic"], 0);
  for (const char* layer : {"lidar", "rgb", "semantic", "vehicle", "coverage"})
    EXPECT_TRUE(std::filesystem::exists(out.path() / (std::string("singapore-onenorth.") + layer + ".tif"))) << layer;
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 10'000u);
}

}  // namespace
}  // namespace nsg::raster
