// `nsgraph export-cloud` on the cached synthetic release: the PCD holds one point
// per covered cell of the scene's own accumulation, read back with PCL and with numpy.
#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "generate_fixture.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/nuscenes/database.h"
#include "nsg/pipeline/export_cloud.h"
#include "nsg/raster/accumulate.h"
#include "nsg/synth/camera_sim.h"
#include "nsg/synth/config.h"
#include "nsg/synth/world.h"
#include "test_support.h"

namespace nsg::pipeline {
namespace {

namespace fs = std::filesystem;
using nuscenes::Database;

class ExportCloud : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    db_ = new Database(Database::load(test::e2e_release(), "v1.0-mini"));
    ASSERT_GE(db_->scene.size(), 3u);
    scene_ = db_->scene[1].name;  // not the first: the restriction must pick the right one
  }
  static void TearDownTestSuite() {
    delete db_;
    db_ = nullptr;
  }
  static test::CommandResult export_scene(const fs::path& out, const std::string& scene, const std::string& format,
                                          int threads = 2) {
    return test::run_nsgraph({"export-cloud", "--dataroot", test::e2e_release().string(), "--version", "v1.0-mini",
                              "--scene", scene, "--out", out.string(), "--encoding", format, "--threads",
                              std::to_string(threads)});
  }

  static inline Database* db_ = nullptr;
  static inline std::string scene_;
};

bool is_paint(synth::GroundMaterial m) {
  return m == synth::GroundMaterial::kPaintWhite || m == synth::GroundMaterial::kPaintYellow ||
         m == synth::GroundMaterial::kCrosswalkPaint;
}

// PCL reads the file back: one point per covered cell of the scene's accumulation, at the
// cell's lowest z with its intensity; lane paint bright, asphalt dark; camera colours and
// labels present.
TEST_F(ExportCloud, PclReadsOnePointPerCoveredCellAtTheLowestZ) {
  test::TempDir tmp("export_cloud");
  const fs::path pcd = tmp / "scene.pcd";
  const test::CommandResult r = export_scene(pcd, scene_, "binary");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(r.out);

  Database db = *db_;
  const raster::LocationLayers layers = accumulate_scene(db, scene_, raster::RasterOptions{}, 1);
  ASSERT_EQ(db.log.size(), db_->log.size());  // the database is restored
  ASSERT_GT(layers.stats.covered_cells, 1000u);

  pcl::PCLPointCloud2 blob;
  ASSERT_EQ(pcl::io::loadPCDFile(pcd.string(), blob), 0);
  std::vector<std::string> names;
  for (const auto& f : blob.fields) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"x", "y", "z", "intensity", "rgb", "label"}));
  pcl::PointCloud<pcl::PointXYZRGBL> rgbl;
  pcl::PointCloud<pcl::PointXYZI> xyzi;
  ASSERT_EQ(pcl::io::loadPCDFile(pcd.string(), rgbl), 0);
  ASSERT_EQ(pcl::io::loadPCDFile(pcd.string(), xyzi), 0);
  ASSERT_EQ(rgbl.size(), layers.stats.covered_cells);
  ASSERT_EQ(xyzi.size(), rgbl.size());
  EXPECT_EQ(summary["points"].get<size_t>(), rgbl.size());
  EXPECT_EQ(summary["sweeps"].get<size_t>(), layers.stats.sweeps);

  const synth::SynthConfig config = synth::SynthConfig::from_file(test::source_dir() / "tests/data/synth/e2e.json");
  const synth::World world = synth::build_world(config, config.seed);
  size_t paint = 0, bright_paint = 0, asphalt = 0, dark_asphalt = 0, coloured = 0, labelled = 0;
  std::set<std::pair<int64_t, int64_t>> cells;
  for (size_t i = 0; i < rgbl.size(); ++i) {
    const pcl::PointXYZRGBL& p = rgbl[i];
    const raster::CellIndex c = raster::cell_of(p.x, p.y, 0.2);
    const raster::LidarCell* cell = layers.lidar.cells().find(c);
    ASSERT_TRUE(cell != nullptr && cell->has_data()) << i;
    ASSERT_EQ(p.z, cell->z) << i;  // the cell's lowest z, bit for bit
    ASSERT_EQ(p.x, cell->x);
    ASSERT_EQ(xyzi[i].intensity, static_cast<float>(cell->intensity));
    ASSERT_TRUE(cells.insert({c.row, c.col}).second) << "cell twice";
    if (i > 0) {  // sorted by (row, col)
      const raster::CellIndex prev = raster::cell_of(rgbl[i - 1].x, rgbl[i - 1].y, 0.2);
      ASSERT_TRUE(prev.row < c.row || (prev.row == c.row && prev.col < c.col)) << i;
    }
    coloured += p.rgba != 0;
    labelled += p.label != kCloudNoLabel;
    // Truth: the material must hold 6 cm around the point (LiDAR range noise at edges).
    const synth::GroundMaterial m = world.ground->material(p.x, p.y);
    bool uniform = true;
    for (double d : {-0.06, 0.06}) {
      const synth::GroundMaterial a = world.ground->material(p.x + d, p.y), b = world.ground->material(p.x, p.y + d);
      uniform = uniform && (is_paint(m) ? is_paint(a) && is_paint(b) : a == m && b == m);
    }
    if (!uniform) continue;
    if (is_paint(m)) {
      ++paint;
      bright_paint += xyzi[i].intensity >= 50;  // synthetic asphalt returns 5..15, paint 70..115
    } else if (m == synth::GroundMaterial::kAsphalt) {
      ++asphalt;
      dark_asphalt += xyzi[i].intensity < 50;
    }
  }
  std::printf(
      "[ figures ] scene %s: %zu points, %zu coloured, %zu labelled; paint %zu (%zu bright), asphalt %zu "
      "(%zu dark)\n",
      scene_.c_str(), rgbl.size(), coloured, labelled, paint, bright_paint, asphalt, dark_asphalt);
  ASSERT_GT(paint, 20u);
  EXPECT_GE(static_cast<double>(bright_paint) / paint, 0.95);
  EXPECT_GE(static_cast<double>(dark_asphalt) / asphalt, 0.95);
  EXPECT_EQ(coloured, summary["rgb_points"].get<size_t>());
  EXPECT_EQ(labelled, summary["labelled_points"].get<size_t>());
  EXPECT_GT(coloured, rgbl.size() / 4);
  EXPECT_GT(labelled, rgbl.size() / 4);
}

// Only the scene's sweeps: each scene's cloud lies at or above the location's layer, and
// the lowest over all scenes' clouds is the location's layer exactly.
TEST_F(ExportCloud, ScenesPartitionTheLocationsSweeps) {
  const Database& db = *db_;
  const std::string location = db.log[db.scene[0].log].location;
  const raster::LocationLayers whole = raster::accumulate_location(db, location, raster::RasterOptions{}, 2);
  std::map<std::pair<int64_t, int64_t>, float> lowest;
  size_t sweeps = 0;
  for (const auto& scene : db_->scene) {
    const raster::LocationLayers one = accumulate_scene(db, scene.name, raster::RasterOptions{}, 2);
    EXPECT_LT(one.stats.sweeps, whole.stats.sweeps);
    sweeps += one.stats.sweeps;
    one.lidar.cells().for_each([&](raster::CellIndex c, const raster::LidarCell& cell) {
      if (!cell.has_data()) return;
      auto [it, fresh] = lowest.try_emplace({c.row, c.col}, cell.z);
      if (!fresh) it->second = std::min(it->second, cell.z);
    });
  }
  EXPECT_EQ(sweeps, whole.stats.sweeps);
  ASSERT_EQ(lowest.size(), whole.stats.covered_cells);
  size_t equal = 0;
  whole.lidar.cells().for_each([&](raster::CellIndex c, const raster::LidarCell& cell) {
    if (cell.has_data()) equal += lowest.at({c.row, c.col}) == cell.z;
  });
  EXPECT_EQ(equal, whole.stats.covered_cells);
}

// A scene list is one map frame: empty lists, scenes of two locations and rows outside the
// scene table are refused; the whole location as a list is accumulate_location.
TEST_F(ExportCloud, SceneListsAreOneLocation) {
  const Database& db = *db_;
  const std::string location = db.log[db.scene[0].log].location;
  const std::vector<nuscenes::Index> scenes = raster::scenes_at(db, location);
  EXPECT_THROW(raster::accumulate_scenes(db, {}, raster::RasterOptions{}, 1), nsg::InternalError);
  EXPECT_THROW(
      raster::accumulate_scenes(db, {static_cast<nuscenes::Index>(db.scene.size())}, raster::RasterOptions{}, 1),
      nsg::InternalError);
  {  // the release has one location: move its last scene to a second one
    ASSERT_GE(scenes.size(), 2u);
    Database two = db;
    nuscenes::Log elsewhere = two.log[two.scene[scenes.back()].log];
    elsewhere.location = "elsewhere";
    two.log.rows().push_back(elsewhere);
    two.scene[scenes.back()].log = static_cast<nuscenes::Index>(two.log.size() - 1);
    EXPECT_THROW(raster::accumulate_scenes(two, {scenes.front(), scenes.back()}, raster::RasterOptions{}, 1),
                 nsg::InternalError);
    EXPECT_THROW(raster::colorize_scenes(two, {scenes.front(), scenes.back()}, raster::LidarLayer{}, {},
                                         raster::CameraOptions{}, 1),
                 nsg::InternalError);
    EXPECT_EQ(raster::scenes_at(two, "elsewhere"), std::vector<nuscenes::Index>{scenes.back()});
  }
  const raster::LocationLayers all = raster::accumulate_scenes(db, scenes, raster::RasterOptions{}, 2);
  const raster::LocationLayers whole = raster::accumulate_location(db, location, raster::RasterOptions{}, 1);
  EXPECT_EQ(all.stats.sweeps, whole.stats.sweeps);
  EXPECT_EQ(all.stats.covered_cells, whole.stats.covered_cells);
  try {
    raster::scenes_at(db, "nowhere");
    ADD_FAILURE() << "no error for an unknown location";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("location nowhere"), std::string::npos) << e.what();
  }
}

// Debian's python3 + numpy parse the header and the binary body; ascii and
// binary_compressed carry the same points; the bytes do not depend on the thread count.
TEST_F(ExportCloud, NumpyParsesTheFileAndFormatsAgree) {
  test::TempDir tmp("export_cloud_py");
  ASSERT_EQ(export_scene(tmp / "b1.pcd", scene_, "binary", 1).exit_code, 0);
  ASSERT_EQ(export_scene(tmp / "b2.pcd", scene_, "binary", 2).exit_code, 0);
  ASSERT_EQ(export_scene(tmp / "a.pcd", scene_, "ascii").exit_code, 0);
  ASSERT_EQ(export_scene(tmp / "c.pcd", scene_, "binary_compressed").exit_code, 0);
  EXPECT_EQ(read_file(tmp / "b1.pcd"), read_file(tmp / "b2.pcd"));

  const std::string script = R"(import sys, numpy as np
data = open(sys.argv[1], 'rb').read()
header = {}
pos = 0
while True:
    end = data.index(b'\n', pos)
    line = data[pos:end].decode('ascii'); pos = end + 1
    if line.startswith('#'): continue
    key, *vals = line.split()
    header[key] = vals
    if key == 'DATA': break
assert header['VERSION'] == ['0.7'], header
assert header['FIELDS'] == ['x', 'y', 'z', 'intensity', 'rgb', 'label'], header
assert header['SIZE'] == ['4'] * 6 and header['TYPE'] == ['F'] * 5 + ['U'], header
assert header['DATA'] == ['binary'], header
n = int(header['POINTS'][0])
assert int(header['WIDTH'][0]) * int(header['HEIGHT'][0]) == n
dt = np.dtype([('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('intensity', '<f4'), ('rgb', '<u4'), ('label', '<u4')])
pts = np.frombuffer(data, dtype=dt, count=n, offset=pos)
assert len(data) == pos + n * dt.itemsize, (len(data), pos, n)
col = np.floor(pts['x'] / 0.2).astype(np.int64); row = np.floor(pts['y'] / 0.2).astype(np.int64)
key = row * (1 << 32) + col
assert np.all(np.diff(key) > 0), 'cells sorted and unique'
print(n, repr(float(pts['z'].astype(np.float64).sum())), int(pts['intensity'].max()), int((pts['rgb'] != 0).sum()))
)";
  test::write_text(tmp / "read_pcd.py", script);
  const test::CommandResult py =
      test::run_program({"/usr/bin/python3", (tmp / "read_pcd.py").string(), (tmp / "b1.pcd").string()});
  ASSERT_EQ(py.exit_code, 0) << py.err;

  pcl::PointCloud<pcl::PointXYZRGBL> b, a, c;
  pcl::PointCloud<pcl::PointXYZI> bi, ai, ci;
  for (auto [file, rgbl, xyzi] :
       {std::tuple{"b1.pcd", &b, &bi}, std::tuple{"a.pcd", &a, &ai}, std::tuple{"c.pcd", &c, &ci}}) {
    ASSERT_EQ(pcl::io::loadPCDFile((tmp / file).string(), *rgbl), 0) << file;
    ASSERT_EQ(pcl::io::loadPCDFile((tmp / file).string(), *xyzi), 0) << file;
  }
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(c.size(), b.size());
  double z_sum = 0;
  size_t coloured = 0;
  float max_intensity = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    z_sum += b[i].z;
    coloured += b[i].rgba != 0;
    max_intensity = std::max(max_intensity, bi[i].intensity);
    ASSERT_EQ(c[i].z, b[i].z);
    ASSERT_EQ(c[i].rgba, b[i].rgba);
    ASSERT_EQ(c[i].label, b[i].label);
    ASSERT_EQ(ci[i].intensity, bi[i].intensity);
    ASSERT_NEAR(a[i].z, b[i].z, 1e-4);  // ascii: 8 significant digits
    ASSERT_EQ(a[i].rgba, b[i].rgba) << i;
    ASSERT_EQ(a[i].label, b[i].label);
    ASSERT_EQ(ai[i].intensity, bi[i].intensity);
  }
  char expected[128];
  std::snprintf(expected, sizeof expected, "%zu ", b.size());
  EXPECT_EQ(py.out.rfind(expected, 0), 0u) << py.out;
  std::istringstream in(py.out);
  size_t n = 0, py_coloured = 0;
  double py_z_sum = 0;
  int py_max_intensity = 0;
  in >> n >> py_z_sum >> py_max_intensity >> py_coloured;
  EXPECT_NEAR(py_z_sum, z_sum, 1e-6 * std::max(1.0, std::abs(z_sum)));
  EXPECT_EQ(py_max_intensity, static_cast<int>(max_intensity));
  EXPECT_EQ(py_coloured, coloured);
  std::printf("[ figures ] %zu points: binary %ju B, ascii %ju B, binary_compressed %ju B\n", b.size(),
              static_cast<uintmax_t>(fs::file_size(tmp / "b1.pcd")),
              static_cast<uintmax_t>(fs::file_size(tmp / "a.pcd")),
              static_cast<uintmax_t>(fs::file_size(tmp / "c.pcd")));
}

TEST_F(ExportCloud, UnknownSceneExitsTwoNamingItAndValidNames) {
  test::TempDir tmp("export_cloud_bad");
  const test::CommandResult r = export_scene(tmp / "x.pcd", "scene-nope", "binary");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("scene-nope"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(db_->scene[0].name), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "x.pcd"));
  const test::CommandResult f = export_scene(tmp / "x.pcd", scene_, "xyz");
  EXPECT_EQ(f.exit_code, 2);
  EXPECT_NE(f.err.find("--encoding"), std::string::npos) << f.err;
}

}  // namespace
}  // namespace nsg::pipeline
