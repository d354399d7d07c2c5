// The tiny synthetic release, generated once per test binary with the real CLI, read back
// with the toolkit's nuScenes reader and checked where the answer is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"
#include "nsg/nuscenes/lidarseg.h"
#include "nsg/nuscenes/map_expansion.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nsg/synth/camera_sim.h"
#include "nsg/synth/config.h"
#include "nsg/synth/lidar_sim.h"
#include "nsg/synth/world.h"
#include "test_support.h"

namespace nsg::synth {
namespace {

namespace fs = std::filesystem;
using nuscenes::Database;
using nuscenes::Index;

fs::path tiny_config_path() { return test::source_dir() / "samples" / "synth" / "tiny.json"; }

// Generates a release with the CLI into a folder that lives until the binary exits.
fs::path generate(const std::string& name, const std::vector<std::string>& extra) {
  static std::vector<std::unique_ptr<test::TempDir>> dirs;
  dirs.push_back(std::make_unique<test::TempDir>(name));
  const fs::path out = dirs.back()->path() / "data";
  std::vector<std::string> args = {"synth", "--config", tiny_config_path().string(), "--out", out.string(), "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  const test::CommandResult r = test::run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return out;
}

// Made with --seed 7 --threads 2 (test::tiny_release).
const fs::path& tiny_release() {
  static const fs::path root = test::tiny_release();
  return root;
}
const Database& tiny_db() {
  static const Database db = Database::load(tiny_release(), "v1.0-mini");
  return db;
}
const World& tiny_world() {
  static const World w = build_world(SynthConfig::from_file(tiny_config_path()), 7);
  return w;
}

std::map<std::string, std::string> hash_tree(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) out[fs::relative(e.path(), root).string()] = sha256_file(e.path());
  return out;
}

// Points of a sample's key LIDAR_TOP sweep in the global frame (the devkit chain).
std::vector<nuscenes::LidarPoint> key_sweep_global(const Database& db, Index sample) {
  const Index sd = db.key_frame(sample, "LIDAR_TOP");
  EXPECT_NE(sd, nuscenes::kNoIndex);
  return nuscenes::load_sweep_global(db, sd);
}

bool inside_box(const nuscenes::SampleAnnotation& ann, const Eigen::Vector3d& p, double margin_m) {
  const Eigen::Matrix3d r = geometry::rotation_matrix(ann.rotation);
  const Eigen::Vector3d local =
      r.transpose() * (p - Eigen::Vector3d(ann.translation[0], ann.translation[1], ann.translation[2]));
  return std::fabs(local.x()) <= ann.size[1] / 2 + margin_m && std::fabs(local.y()) <= ann.size[0] / 2 + margin_m &&
         std::fabs(local.z()) <= ann.size[2] / 2 + margin_m;
}

// Returns from vehicles/pedestrians near the ground are not ground returns.
bool near_annotated_object(const Database& db, Index sample, const nuscenes::LidarPoint& p, double margin_m) {
  for (Index a : db.sample[sample].anns)
    if (inside_box(db.sample_annotation[a], Eigen::Vector3d(p.x, p.y, p.z), margin_m)) return true;
  return false;
}

// nuScenes-lidarseg: one record per key-frame LIDAR_TOP sweep, keyed by its sample_data
// token, one label per point; the 32 categories carry the lidarseg index of their name.
TEST(WorldRelease, WritesLidarsegForEveryKeyFrameSweep) {
  const Database& db = tiny_db();
  for (const nuscenes::Category& c : db.category) {
    ASSERT_TRUE(c.index.has_value()) << c.name;
    EXPECT_EQ(nuscenes::lidarseg_class_names().at(static_cast<size_t>(*c.index)), c.name);
  }
  const nuscenes::LidarsegIndex index = nuscenes::LidarsegIndex::load(db);
  size_t key_sweeps = 0;
  std::map<uint8_t, size_t> counts;
  std::vector<uint8_t> labels;
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    if (sd.modality != nuscenes::Modality::kLidar) continue;
    if (!sd.is_key_frame) {
      EXPECT_TRUE(index.labels_file(i).empty());
      continue;
    }
    ++key_sweeps;
    const fs::path file = index.labels_file(i);
    EXPECT_EQ(file, tiny_release() / "lidarseg" / "v1.0-mini" / (sd.token.str() + "_lidarseg.bin"));
    const std::vector<nuscenes::LidarPoint> points = nuscenes::read_lidar_points(db.file_path(sd));
    nuscenes::read_lidarseg_labels(file, points.size(), labels);
    for (size_t p = 0; p < points.size(); ++p) {
      ++counts[labels[p]];
      // The roof returns (|x|, |y| < 1 m in the sensor frame) are the ego vehicle.
      if (std::abs(points[p].x) < 1.0f && std::abs(points[p].y) < 1.0f && points[p].z < 0.0f) {
        EXPECT_EQ(labels[p], 31) << p;
      }
    }
  }
  EXPECT_EQ(index.labelled_sweeps(), key_sweeps);
  EXPECT_EQ(key_sweeps, db.sample.size());
  for (const auto& [label, n] : counts) EXPECT_LT(label, 32) << n;
  // The street: driveable surface, sidewalks, buildings and the ego all appear.
  for (uint8_t label : {24, 26, 28, 31}) EXPECT_GT(counts[label], 100u) << int(label);
}

TEST(WorldRelease, LoadsWithTheToolkitReader) {
  const Database& db = tiny_db();
  EXPECT_EQ(db.scene.size(), 2u);
  EXPECT_EQ(db.sample.size(), 8u);
  EXPECT_EQ(db.sensor.size(), 12u);
  EXPECT_EQ(db.category.size(), 32u);  // nuScenes-lidarseg's category.json: all with index
  EXPECT_EQ(db.attribute.size(), 8u);
  EXPECT_EQ(db.visibility.size(), 4u);
  EXPECT_EQ(db.map.size(), 1u);
  EXPECT_EQ(db.calibrated_sensor.size(), 24u);
  EXPECT_EQ(db.ego_pose.size(), db.sample_data.size());
  EXPECT_GT(db.sample_annotation.size(), 10u);
  EXPECT_EQ(db.scene[0].name, "scene-0061");
  for (const auto& sd : db.sample_data) {
    EXPECT_TRUE(fs::is_regular_file(db.file_path(sd))) << sd.filename;
    if (sd.fileformat == "jpg") {
      const fs::path png =
          tiny_release() / "semantic" / db.channel(sd) / fs::path(sd.filename).filename().replace_extension(".png");
      EXPECT_TRUE(fs::is_regular_file(png)) << png;
      EXPECT_EQ(sd.width, 1600);
      EXPECT_EQ(sd.height, 900);
    } else {
      EXPECT_EQ(fs::file_size(db.file_path(sd)) % 20, 0u);
    }
  }
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion(tiny_release(), "boston-seaport");
  EXPECT_EQ(map.version(), "1.3");
  EXPECT_GT(map.lanes().size(), 20u);
  EXPECT_GT(map.lane_connectors().size(), 20u);
  const nuscenes::GrayImage prior = nuscenes::read_semantic_mask(tiny_release() / db.map[0].filename);
  EXPECT_EQ(prior.width, 3000);
  EXPECT_EQ(prior.height, 3000);
  EXPECT_TRUE(fs::is_regular_file(tiny_release() / "maps" / "basemap" / "boston-seaport.png"));
  // A map pixel on a lane centre is drivable (255), the map corner is not.
  const geometry::Pose2 p = map.discretize_lane(map.lanes()[0].token, 1.0)[3];
  EXPECT_EQ(prior.at(static_cast<int>(std::lround(p.x * 10)), static_cast<int>(std::lround(3000 - p.y * 10))), 255);
  EXPECT_EQ(prior.at(5, 5), 0);
}

TEST(WorldRelease, TablesArePythonIndent0Style) {
  const std::string text = read_file(tiny_release() / "v1.0-mini" / "sample_data.json");
  ASSERT_EQ(text.rfind("[\n{\n\"token\": \"", 0), 0u);
  EXPECT_EQ(text.find("\n "), std::string::npos);  // no indentation
  EXPECT_EQ(text.back(), ']');
  // Key order as in the real files.
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
  std::vector<std::string> keys;
  for (auto it = j[0].begin(); it != j[0].end(); ++it) keys.push_back(it.key());
  EXPECT_EQ(keys,
            (std::vector<std::string>{"token", "sample_token", "ego_pose_token", "calibrated_sensor_token", "timestamp",
                                      "fileformat", "is_key_frame", "height", "width", "filename", "prev", "next"}));
  const std::string ego = read_file(tiny_release() / "v1.0-mini" / "ego_pose.json");
  EXPECT_NE(ego.find("\"timestamp\": 15"), std::string::npos);
  EXPECT_NE(ego.find(",\n0.0\n]"), std::string::npos);  // translation z written as 0.0
  const std::string vis = read_file(tiny_release() / "v1.0-mini" / "visibility.json");
  EXPECT_NE(vis.find("\"token\": \"4\""), std::string::npos);
  const std::string cal = read_file(tiny_release() / "v1.0-mini" / "calibrated_sensor.json");
  EXPECT_NE(cal.find("\"camera_intrinsic\": []"), std::string::npos);
  EXPECT_NE(cal.find("[\n1266.417203046554,\n0.0,\n816.2670197447984\n]"), std::string::npos);
}

// The timing rules of real data (docs/nuscenes-input.md), checked on any release.
void check_timing_rules(const Database& db, const std::vector<std::string>& channels) {
  std::map<std::string, std::vector<Index>> by_scene_channel;
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const auto& sd = db.sample_data[i];
    const auto& ep = db.ego_pose[sd.ego_pose];
    EXPECT_EQ(ep.token, sd.token);
    EXPECT_EQ(ep.timestamp_us, sd.timestamp_us);
    EXPECT_EQ(ep.translation[2], 0.0);
    const auto& smp = db.sample[sd.sample];
    const std::string ch = db.channel(sd);
    by_scene_channel[std::to_string(smp.scene) + "/" + ch].push_back(i);
    const std::string logfile = db.log[db.scene[smp.scene].log].logfile;
    const std::string expect = std::string(sd.is_key_frame ? "samples/" : "sweeps/") + ch + "/" + logfile + "__" + ch +
                               "__" + std::to_string(sd.timestamp_us) + (sd.fileformat == "pcd" ? ".pcd.bin" : ".jpg");
    EXPECT_EQ(sd.filename, expect);
    if (sd.is_key_frame && ch == "LIDAR_TOP") {
      EXPECT_EQ(smp.timestamp_us, sd.timestamp_us);
    } else if (!sd.is_key_frame) {
      // Non-key frames point to the sample that follows them.
      EXPECT_GT(smp.timestamp_us, sd.timestamp_us);
      if (smp.prev != nuscenes::kNoIndex) {
        EXPECT_LE(db.sample[smp.prev].timestamp_us, sd.timestamp_us);
      }
    }
  }
  for (Index s = 0; s < static_cast<Index>(db.sample.size()); ++s) {
    for (const std::string& ch : channels) {
      const Index key = db.key_frame(s, ch);
      ASSERT_NE(key, nuscenes::kNoIndex) << ch;
      // The key camera frame is the closest in time of its channel in the scene.
      const auto& frames = by_scene_channel[std::to_string(db.sample[s].scene) + "/" + ch];
      const int64_t ts = db.sample[s].timestamp_us;
      for (Index f : frames)
        EXPECT_LE(std::llabs(db.sample_data[key].timestamp_us - ts), std::llabs(db.sample_data[f].timestamp_us - ts));
    }
  }
  // prev/next chains per channel run through all frames in time order.
  for (const auto& [key, frames] : by_scene_channel) {
    size_t heads = 0;
    for (Index f : frames) {
      const auto& sd = db.sample_data[f];
      if (sd.prev == nuscenes::kNoIndex) ++heads;
      if (sd.next != nuscenes::kNoIndex) {
        EXPECT_EQ(db.sample_data[sd.next].prev, f);
        EXPECT_GT(db.sample_data[sd.next].timestamp_us, sd.timestamp_us);
        EXPECT_EQ(db.sample_data[sd.next].sensor, sd.sensor);
      }
    }
    EXPECT_EQ(heads, 1u) << key;
  }
}

TEST(WorldRelease, TimingRules) {
  check_timing_rules(tiny_db(), {"LIDAR_TOP", "CAM_FRONT", "CAM_BACK"});
  // 20 Hz LiDAR: 10 sweeps per key-frame interval, 4 samples.
  size_t sweeps = 0;
  for (const auto& sd : tiny_db().sample_data)
    sweeps += sd.fileformat == "pcd" && tiny_db().sample[sd.sample].scene == 0;
  EXPECT_EQ(sweeps, 31u);
}

// scenes.capture_days spreads the scenes over days in index order: each scene's log has its
// day's date (and the same time of day as with one day), and the timing rules still hold.
TEST(WorldRelease, CaptureDaysGiveEachSceneItsDate) {
  const fs::path root = generate("synth-days", {"--set", "scenes.count=3", "--set", "scenes.capture_days=3", "--set",
                                                "scenes.samples_per_scene=2"});
  const Database db = Database::load(root, "v1.0-mini");
  ASSERT_EQ(db.scene.size(), 3u);
  std::vector<std::string> dates;
  for (const auto& scene : db.scene) dates.push_back(db.log[scene.log].date_captured);
  // tiny.json's first sample is on 2018-07-23 in Boston (UTC−4); scene i is shifted by i days.
  EXPECT_EQ(dates, (std::vector<std::string>{"2018-07-23", "2018-07-24", "2018-07-25"}));
  const int64_t day_us = int64_t{86400} * 1000000;
  const int64_t t0 = db.sample[db.scene[0].first_sample].timestamp_us;
  const int64_t t1 = db.sample[db.scene[1].first_sample].timestamp_us;
  EXPECT_GE(t1 - t0, day_us);
  EXPECT_LT(t1 - t0, day_us + int64_t{600} * 1000000);  // a minute or so after, a day later
  check_timing_rules(db, {"LIDAR_TOP", "CAM_FRONT"});
}

// Cameras at their real 12 Hz: non-key camera frames in sweeps/, key = closest in time.
TEST(WorldRelease, TimingRulesWithTwelveHertzCameras) {
  test::TempDir dir("synth-cam12");
  nlohmann::json cfg = nlohmann::json::parse(read_file(tiny_config_path()));
  cfg["scenes"]["count"] = 1;
  cfg["scenes"]["samples_per_scene"] = 3;
  cfg["lidar"]["points_per_sweep"] = 2000;
  cfg["lidar"]["roof_points"] = 200;
  cfg["camera"]["rate_hz"] = 12.0;
  cfg["camera"]["channels"] = {"CAM_FRONT_LEFT"};
  test::write_text(dir / "cfg.json", cfg.dump());
  const test::CommandResult r =
      test::run_nsgraph({"synth", "--config", (dir / "cfg.json").string(), "--out", (dir / "data").string(), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Database db = Database::load(dir / "data", "v1.0-mini");
  check_timing_rules(db, {"LIDAR_TOP", "CAM_FRONT_LEFT"});
  size_t cams = 0, keys = 0;
  for (const auto& sd : db.sample_data) {
    if (sd.fileformat != "jpg") continue;
    ++cams;
    keys += sd.is_key_frame;
  }
  EXPECT_EQ(keys, 3u);
  EXPECT_GE(cams, 12u);  // 1 s between the first and last key frame at 12 Hz
}

TEST(WorldRelease, LanePaintSeenByLidarIsBright) {
  const Database& db = tiny_db();
  const World& w = tiny_world();
  const GroundRaster& g = *w.ground;
  size_t paint = 0, asphalt = 0;
  double asphalt_sum = 0.0;
  for (Index s = 0; s < static_cast<Index>(db.sample.size()); ++s) {
    for (const auto& p : key_sweep_global(db, s)) {
      if (std::fabs(p.z) > 0.08 || near_annotated_object(db, s, p, 0.3)) continue;  // on the road surface
      const GroundMaterial m = g.material(p.x, p.y);
      bool uniform = true;
      for (double dx : {-0.04, 0.04})
        for (double dy : {-0.04, 0.04}) uniform &= g.material(p.x + dx, p.y + dy) == m;
      if (!uniform) continue;
      if (m == GroundMaterial::kPaintWhite || m == GroundMaterial::kPaintYellow ||
          m == GroundMaterial::kCrosswalkPaint) {
        EXPECT_GE(p.intensity, 0.6 * lidar_ground_intensity(m)) << p.x << "," << p.y;
        ++paint;
      } else if (m == GroundMaterial::kAsphalt) {
        asphalt_sum += p.intensity;
        ++asphalt;
      }
    }
  }
  EXPECT_GT(paint, 20u);
  ASSERT_GT(asphalt, 100u);
  EXPECT_LT(asphalt_sum / asphalt, 0.5 * lidar_ground_intensity(GroundMaterial::kPaintWhite));
}

TEST(WorldRelease, ParkedCarPointsLieInsideTheirBox) {
  const Database& db = tiny_db();
  Index parked_attr = nuscenes::kNoIndex;
  for (Index a = 0; a < static_cast<Index>(db.attribute.size()); ++a)
    if (db.attribute[a].name == "vehicle.parked") parked_attr = a;
  ASSERT_NE(parked_attr, nuscenes::kNoIndex);
  int checked = 0;
  for (const auto& ann : db.sample_annotation) {
    if (ann.attributes.empty() || ann.attributes[0] != parked_attr || ann.num_lidar_pts < 5) continue;
    int inside = 0;
    for (const auto& p : key_sweep_global(db, ann.sample))
      inside += inside_box(ann, Eigen::Vector3d(p.x, p.y, p.z), 0.0);
    EXPECT_GE(inside, 1);
    EXPECT_NEAR(inside, ann.num_lidar_pts, 2 + 0.02 * ann.num_lidar_pts);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// A LiDAR ground point projected into the key CAM_FRONT image with the devkit chain lands
// on a pixel of the class and (within texture, noise and JPEG error) the colour of its
// ground material.
TEST(WorldRelease, GroundPointsProjectToTheExpectedCameraClass) {
  const Database& db = tiny_db();
  const GroundRaster& g = *tiny_world().ground;
  nuscenes::JpegDecoder decoder;
  size_t total = 0, same = 0, colour = 0;
  for (Index s = 0; s < static_cast<Index>(db.sample.size()); ++s) {
    const Index cam = db.key_frame(s, "CAM_FRONT");
    const auto& sd = db.sample_data[cam];
    const auto& ep = db.ego_pose[sd.ego_pose];
    const auto& cs = db.calibrated_sensor[sd.calibrated_sensor];
    const nuscenes::GrayImage mask = nuscenes::read_semantic_mask(
        tiny_release() / "semantic" / "CAM_FRONT" / fs::path(sd.filename).filename().replace_extension(".png"));
    ASSERT_EQ(mask.width, 1600);
    const nuscenes::RgbImage rgb = decoder.decode_file(db.file_path(sd));
    ASSERT_EQ(rgb.width, 1600);
    const Eigen::Matrix3d r_ego = geometry::rotation_matrix(ep.rotation), r_cs = geometry::rotation_matrix(cs.rotation);
    const auto& k = *cs.camera_intrinsic;
    for (const auto& p : key_sweep_global(db, s)) {
      if (p.z > 0.3) continue;
      const GroundMaterial m = g.material(p.x, p.y);
      bool uniform = true;
      for (double dx : {-0.15, 0.0, 0.15})
        for (double dy : {-0.15, 0.0, 0.15}) uniform &= g.material(p.x + dx, p.y + dy) == m;
      if (!uniform || std::fabs(p.z - material_height_m(m)) > 0.08) continue;
      Eigen::Vector3d q(p.x, p.y, p.z);
      q = r_ego.transpose() * (q - Eigen::Vector3d(ep.translation[0], ep.translation[1], ep.translation[2]));
      q = r_cs.transpose() * (q - Eigen::Vector3d(cs.translation[0], cs.translation[1], cs.translation[2]));
      if (q.z() <= 1.0) continue;
      const double u = (k[0][0] * q.x() + k[0][1] * q.y() + k[0][2] * q.z()) / q.z();
      const double v = (k[1][0] * q.x() + k[1][1] * q.y() + k[1][2] * q.z()) / q.z();
      if (!(u > 1 && u < 1599 && v > 1 && v < 899)) continue;
      ++total;
      const int pu = static_cast<int>(std::lround(u)), pv = static_cast<int>(std::lround(v));
      same += mask.at(pu, pv) == static_cast<uint8_t>(ground_class(m));
      const std::array<uint8_t, 3> base = ground_base_rgb(m);
      double diff = 0.0;
      for (int c = 0; c < 3; ++c)
        diff += std::fabs(static_cast<double>(rgb.at(pu, pv)[c]) - base[static_cast<size_t>(c)]);
      colour += diff / 3.0 < 40.0;
    }
  }
  ASSERT_GT(total, 200u);
  EXPECT_GT(static_cast<double>(same) / total, 0.9) << same << " of " << total;
  EXPECT_GT(static_cast<double>(colour) / total, 0.85) << colour << " of " << total;
}

TEST(WorldRelease, DetectionsListEverySample) {
  const Database& db = tiny_db();
  const nlohmann::json det =
      nlohmann::json::parse(read_file(tiny_release() / "detections" / "synthetic_detector.json"));
  ASSERT_TRUE(det.contains("meta"));
  EXPECT_EQ(det["results"].size(), db.sample.size());
  size_t boxes = 0;
  for (const auto& smp : db.sample) {
    const auto& list = det["results"].at(smp.token.str());
    for (const auto& b : list) {
      EXPECT_EQ(b["sample_token"], smp.token.str());
      EXPECT_EQ(b["velocity"].size(), 2u);
      const double score = b["detection_score"];
      EXPECT_TRUE(score >= 0.0 && score <= 1.0);
      ++boxes;
    }
  }
  EXPECT_GT(boxes, 5u);
}

TEST(WorldRelease, SameSeedIsByteIdenticalDifferentSeedDiffers) {
  const auto a = hash_tree(tiny_release());
  const auto b = hash_tree(generate("synth-same", {"--threads", "1"}));
  EXPECT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "same seed, different thread count gave different bytes";
  const auto c = hash_tree(generate("synth-other", {"--seed", "8"}));
  EXPECT_NE(a.at("v1.0-mini/sample_annotation.json"), c.at("v1.0-mini/sample_annotation.json"));
  EXPECT_NE(a.at("maps/expansion/boston-seaport.json"), c.at("maps/expansion/boston-seaport.json"));
}

TEST(WorldCli, BadConfigExitsTwoNamingTheKey) {
  test::TempDir dir("synth-bad");
  test::write_text(dir / "bad.json", R"({"location": "boston-seaport", "lidar": {"points_per_swep": 10}})");
  const test::CommandResult r =
      test::run_nsgraph({"synth", "--config", (dir / "bad.json").string(), "--out", (dir / "out").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("lidar.points_per_swep"), std::string::npos) << r.err;
  test::write_text(dir / "bad2.json", R"({"location": "atlantis"})");
  const test::CommandResult r2 =
      test::run_nsgraph({"synth", "--config", (dir / "bad2.json").string(), "--out", (dir / "out").string()});
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("location"), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "v1.0-mini"));
}

}  // namespace
}  // namespace nsg::synth
