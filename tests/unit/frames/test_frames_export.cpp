// `nsgraph frames` end to end on the e2e release and dataset: every key frame exported or
// counted, records equal to the release (pose, calibration, images), the ground truth on
// the map's own lane graph and inside the window, links only where lanes join, the leakage
// figures, determinism, images copied, and bad input refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "generate_fixture.h"
#include "nsg/core/sha256.h"
#include "nsg/geometry/transform.h"
#include "nsg/graph/from_map.h"
#include "nsg/graph/segment_index.h"
#include "nsg/nuscenes/database.h"
#include "nsg/metrics/frames_documents.h"
#include "nsg/nuscenes/map_expansion.h"
#include "nsg/validate/schema.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kVersion = "v1.0-mini";

CommandResult frames(const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"frames", "--quiet", "--dataset", e2e_dataset().string(), "--out", out.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return run_nsgraph(args);
}

int64_t sum(const json& counts) {
  int64_t n = 0;
  for (const auto& [k, v] : counts.items()) n += v.get<int64_t>();
  return n;
}

Eigen::Matrix3d matrix(const json& rows) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = rows[r][c].get<double>();
  return m;
}

Eigen::Vector3d vec(const json& v) { return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()}; }

void expect_schema(const fs::path& schema, const json& doc, const std::string& label) {
  const Issues issues = validate::validate_against_schema(schema, doc, label, "schema");
  EXPECT_TRUE(issues.empty()) << label << ": "
                              << (issues.empty() ? "" : issues.items()[0].subject + " " + issues.items()[0].message);
}

// One export of the e2e dataset with every frame kept, shared by the tests that read it.
const fs::path& kept_export() {
  static const fs::path dir = [] {
    static TempDir tmp("frames-kept");
    const CommandResult r = frames(tmp / "out", {"--overlap", "keep"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return tmp / "out";
  }();
  return dir;
}

std::vector<json> records(const fs::path& dir) {
  std::vector<json> out;
  const json manifest = read_json(dir / "manifest.json");  // kept: the loop reads into it
  for (const json& f : manifest["files"])
    if (f["path"].get<std::string>().find("/info/") != std::string::npos)
      out.push_back(read_json(dir / f["path"].get<std::string>()));
  return out;
}

TEST(FramesExport, EveryKeyFrameIsExportedOrCountedAndEveryFileIsListed) {
  const fs::path& dir = kept_export();
  const json manifest = read_json(dir / "manifest.json");
  const fs::path schemas = source_dir() / "schemas/v1";
  expect_schema(schemas / "frames-manifest.schema.json", manifest, "manifest.json");
  const json& counts = manifest["counts"];
  const json samples = read_json(e2e_release() / kVersion / "sample.json");
  EXPECT_EQ(counts["key_frames"], samples.size());
  EXPECT_EQ(sum(counts["frames"]) + sum(counts["dropped"]), counts["key_frames"].get<int64_t>());
  EXPECT_EQ(counts["dropped"]["overlap"], 0);  // --overlap keep
  EXPECT_GT(counts["frames"]["train"].get<int64_t>(), 0);
  EXPECT_GT(counts["frames"]["test"].get<int64_t>(), 0);
  // Every file listed with its size and digest, and nothing else written.
  std::set<std::string> listed;
  for (const json& f : manifest["files"]) {
    const fs::path p = dir / f["path"].get<std::string>();
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(fs::file_size(p), f["bytes"].get<uint64_t>());
    EXPECT_EQ(sha256_file(p), f["sha256"]);
    listed.insert(f["path"].get<std::string>());
  }
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != "manifest.json") {
      EXPECT_TRUE(listed.count(fs::relative(e.path(), dir).generic_string())) << e.path();
    }
  }
  // data_dict.json: OpenLane-V2's {split: {segment: [<timestamp>.json]}}, one entry per record.
  const json dict = read_json(dir / "data_dict.json");
  int64_t entries = 0;
  for (const auto& [split, segments] : dict.items())
    for (const auto& [segment, names] : segments.items())
      for (const json& name : names) {
        ++entries;
        EXPECT_TRUE(listed.count(split + "/" + segment + "/info/" + name.get<std::string>())) << name;
      }
  EXPECT_EQ(entries, sum(counts["frames"]));
  const std::vector<json> all = records(dir);
  EXPECT_EQ(static_cast<int64_t>(all.size()), entries);
  for (const json& r : all) expect_schema(schemas / "frame.schema.json", r, r["sample_token"]);
}

TEST(FramesExport, RecordsCarryTheReleasesPoseCalibrationAndImages) {
  const nuscenes::Database db = nuscenes::Database::load(e2e_release(), kVersion);
  const json dataset = read_json(e2e_dataset() / "manifest.json");
  std::map<std::string, nuscenes::Index> by_token;
  for (size_t i = 0; i < db.sample.size(); ++i)
    by_token[db.sample.rows()[i].token.str()] = static_cast<nuscenes::Index>(i);
  const std::vector<json> all = records(kept_export());
  ASSERT_FALSE(all.empty());
  for (const json& r : all) {
    const nuscenes::Index s = by_token.at(r["sample_token"].get<std::string>());
    EXPECT_EQ(r["timestamp"], db.sample[s].timestamp_us);
    EXPECT_EQ(r["segment_id"], db.scene[db.sample[s].scene].name);
    const nuscenes::SampleData& lidar = db.sample_data[db.key_frame(s, "LIDAR_TOP")];
    const nuscenes::EgoPose& pose = db.ego_pose[lidar.ego_pose];
    EXPECT_TRUE(matrix(r["pose"]["rotation"]).isApprox(geometry::rotation_matrix(pose.rotation), 1e-12));
    EXPECT_EQ(vec(r["pose"]["translation"]),
              Eigen::Vector3d(pose.translation[0], pose.translation[1], pose.translation[2]));
    // The split is that of the region holding the ego.
    std::string split;
    for (const json& region : dataset["locations"][0]["regions"]) {
      const json& b = region["bounds_m"];
      if (pose.translation[0] >= b[0] && pose.translation[0] <= b[2] && pose.translation[1] >= b[1] &&
          pose.translation[1] <= b[3])
        split = region["split"];
    }
    EXPECT_EQ(r["split"], split);
    size_t cameras = 0;
    for (const nuscenes::SampleDataRef& ref : db.sample[s].data) {
      const nuscenes::SampleData& sd = db.sample_data[ref.sample_data];
      if (sd.modality != nuscenes::Modality::kCamera) continue;
      ++cameras;
      const json& cam = r["sensor"][db.channel(sd)];
      EXPECT_EQ(cam["image_path"], sd.filename);
      EXPECT_TRUE(fs::exists(e2e_release() / sd.filename));
      const nuscenes::CalibratedSensor& cs = db.calibrated_sensor[sd.calibrated_sensor];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) EXPECT_EQ(cam["intrinsic"]["K"][a][b], (*cs.camera_intrinsic)[a][b]);
      EXPECT_TRUE(matrix(cam["extrinsic"]["rotation"]).isApprox(geometry::rotation_matrix(cs.rotation), 1e-12));
      EXPECT_EQ(cam["extrinsic"]["translation"][0], cs.translation[0]);
    }
    EXPECT_EQ(r["sensor"].size(), cameras);
    EXPECT_GT(cameras, 0u);  // e2e.json's release has two of the six
  }
}

TEST(FramesExport, CenterlinesLieOnTheMapsLaneGraphInsideTheWindowAndLinkWhereLanesJoin) {
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion(e2e_release(), "boston-seaport");
  Issues issues;
  const graph::LaneGraph g = graph::build_lane_graph(map, graph::LaneGraphOptions{}, &issues);
  int64_t centerlines = 0, links = 0;
  for (const json& r : records(kept_export())) {
    const Eigen::Matrix3d rot = matrix(r["pose"]["rotation"]);
    const Eigen::Vector3d t = vec(r["pose"]["translation"]);
    const json& lanes = r["annotation"]["lane_centerline"];
    for (const json& lane : lanes) {
      ++centerlines;
      for (const char* key : {"points", "points_2m"})
        for (const json& p : lane[key]) {
          const Eigen::Vector3d ego = vec(p);
          EXPECT_GE(ego.x(), -50.0 - 1e-4);
          EXPECT_LE(ego.x(), 50.0 + 1e-4);
          EXPECT_GE(ego.y(), -25.0 - 1e-4);
          EXPECT_LE(ego.y(), 25.0 + 1e-4);
          const Eigen::Vector3d global = rot * ego + t;
          EXPECT_NEAR(global.z(), 0.0, 1e-3);  // the map plane
          // On the lane it names (lanes share their end nodes, so the nearest edge may be another's).
          const int32_t l = g.find_lane(lane["lane_token"]);
          ASSERT_GE(l, 0) << lane["lane_token"];
          const std::vector<int32_t>& chain = g.lanes[static_cast<size_t>(l)].nodes;
          double nearest = 1e9;
          for (size_t k = 1; k < chain.size(); ++k) {
            const graph::Node& a = g.nodes[static_cast<size_t>(chain[k - 1])];
            const graph::Node& b = g.nodes[static_cast<size_t>(chain[k])];
            nearest = std::min(
                nearest, graph::closest_on_segment(a.x_m, a.y_m, b.x_m, b.y_m, global.x(), global.y()).distance_m);
          }
          EXPECT_LT(nearest, 1e-3) << lane["lane_token"];
        }
      // `points`: 11 evenly spaced along the piece.
      const json& pts = lane["points"];
      ASSERT_EQ(pts.size(), 11u);
      double first = -1.0;
      for (size_t i = 1; i < pts.size(); ++i) {
        const double d = (vec(pts[i]) - vec(pts[i - 1])).norm();
        if (first < 0) first = d;
        EXPECT_NEAR(d, first, 2e-3 + 0.02 * first);  // a curved piece's chords are a little shorter
      }
    }
    const json& topo = r["annotation"]["topology_lclc"];
    ASSERT_EQ(topo.size(), lanes.size());
    for (size_t i = 0; i < lanes.size(); ++i) {
      ASSERT_EQ(topo[i].size(), lanes.size());
      EXPECT_EQ(r["annotation"]["topology_lcte"][i].size(), 0u);
      for (size_t j = 0; j < lanes.size(); ++j) {
        if (topo[i][j] == 0) continue;
        ++links;
        EXPECT_TRUE(lanes[i]["ends_at_lane_end"].get<bool>());
        EXPECT_TRUE(lanes[j]["starts_at_lane_start"].get<bool>());
        EXPECT_LT((vec(lanes[i]["points"].back()) - vec(lanes[j]["points"][0])).norm(), 2e-4);
      }
    }
  }
  const json counts = read_json(kept_export() / "manifest.json")["counts"];
  EXPECT_EQ(counts["centerlines"], centerlines);
  EXPECT_EQ(counts["links"], links);
  EXPECT_GT(links, 0);
}

// Distance from `p` to the polyline `line` (x, y).
double distance_to(const json& line, const Eigen::Vector3d& p) {
  double best = 1e9;
  for (size_t k = 1; k < line.size(); ++k) {
    const Eigen::Vector3d a = vec(line[k - 1]), b = vec(line[k]);
    best = std::min(best, graph::closest_on_segment(a.x(), a.y(), b.x(), b.y(), p.x(), p.y()).distance_m);
  }
  return best;
}

// Version 2: a lane segment per centerline (same id, same topology), its lanelines half the
// e2e world's 3.5 m lane width to either side (left of the driving direction first), and
// areas inside the window, crossings closed; the manifest counts what the records hold.
TEST(FramesExport, LaneSegmentsAreTheCenterlinesWithTheirLanelinesAndAreasLieInTheWindow) {
  int64_t crossings = 0, boundaries = 0, segments = 0;
  for (const json& r : records(kept_export())) {
    ASSERT_EQ(r["version"], "nsgraph-frames-2");
    const json& a = r["annotation"];
    const json& lanes = a["lane_centerline"];
    ASSERT_EQ(a["lane_segment"].size(), lanes.size());
    EXPECT_EQ(a["topology_lsls"], a["topology_lclc"]);
    EXPECT_EQ(a["topology_lste"], a["topology_lcte"]);
    for (size_t i = 0; i < lanes.size(); ++i) {
      const json& s = a["lane_segment"][i];
      ++segments;
      EXPECT_EQ(s["id"], lanes[i]["id"]);
      EXPECT_EQ(s["is_intersection_or_connector"], lanes[i]["is_intersection_or_connector"]);
      const json& center = s["centerline"];
      ASSERT_EQ(center.size(), 10u);
      EXPECT_LT((vec(center[0]) - vec(lanes[i]["points"][0])).norm(), 2e-4);
      EXPECT_LT((vec(center[9]) - vec(lanes[i]["points"][10])).norm(), 2e-4);
      for (const char* side : {"left_laneline", "right_laneline"}) {
        ASSERT_EQ(s[side].size(), 10u) << side;
        const double sign = std::string(side) == "left_laneline" ? 1.0 : -1.0;
        for (size_t k = 0; k < 10; ++k) {
          const Eigen::Vector3d p = vec(s[side][k]);
          // Lanes of a curve are cut where the piece's ends project: 0.3 m of slack there.
          EXPECT_NEAR(distance_to(center, p), 1.75, 0.3) << side << " of " << s["id"];
          const size_t j = std::min<size_t>(k, 8);
          const Eigen::Vector3d d = vec(center[j + 1]) - vec(center[j]);
          const Eigen::Vector3d off = p - vec(center[k]);
          EXPECT_GT(sign * (d.x() * off.y() - d.y() * off.x()), 0.0) << side << " of " << s["id"];
        }
      }
    }
    for (const json& area : a["area"]) {
      const int category = area["category"];
      ASSERT_TRUE(category == 1 || category == 2);
      ++(category == 1 ? crossings : boundaries);
      for (const json& p : area["points"]) {
        EXPECT_LE(std::abs(p[0].get<double>()), 50.0 + 1e-4);
        EXPECT_LE(std::abs(p[1].get<double>()), 25.0 + 1e-4);
      }
      if (category == 1) EXPECT_EQ(area["points"].front(), area["points"].back());
    }
  }
  const json counts = read_json(kept_export() / "manifest.json")["counts"];
  EXPECT_EQ(counts["centerlines"], segments);
  EXPECT_EQ(counts["areas"]["pedestrian_crossing"], crossings);
  EXPECT_EQ(counts["areas"]["road_boundary"], boundaries);
  EXPECT_GT(crossings, 0);
  EXPECT_GT(boundaries, 0);
  EXPECT_GT(counts["lanelines_from_offset"].get<int64_t>(), 0);  // the connectors
  EXPECT_LT(counts["lanelines_from_offset"].get<int64_t>(), 2 * segments);
}

TEST(FramesExport, LeakageIsZeroOnTheRegionsAndMeasuredForAScenesRandomSplit) {
  const CommandResult r =
      run_nsgraph({"frames", "--quiet", "--dataset", e2e_dataset().string(), "--stats", "--overlap", "keep"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json stats = json::parse(r.out);
  const json& regions = stats["leakage"]["regions"];
  ASSERT_GT(regions["test_frames"].get<int64_t>(), 0);
  EXPECT_EQ(regions["test_within_radius"], 0);
  EXPECT_EQ(regions["share_within_radius"], 0.0);
  // Different splits' regions are at least the 25.6 m buffer apart, so are their egos.
  EXPECT_GE(regions["median_distance_m"].get<double>(), 25.6);
  const json& random = stats["leakage"]["scenes_random"];
  EXPECT_EQ(random["test_frames"].get<int64_t>() + random["train_frames"].get<int64_t>() <= sum(stats["frames"]), true);
  // The manifest carries the same figures.
  EXPECT_EQ(read_json(kept_export() / "manifest.json")["counts"]["leakage"], stats["leakage"]);
}

// An export's exit code: 1 when it kept no frame (NoFrameKeptIsAFailedRunThatSaysWhy), else 0.
int expected_exit(const fs::path& out) {
  return sum(read_json(out / "manifest.json")["counts"]["frames"]) == 0 ? 1 : 0;
}

TEST(FramesExport, DroppingAndFlaggingCountTheSameFrames) {
  TempDir tmp("frames-overlap");
  const CommandResult dropped = frames(tmp / "drop");  // the e2e world's frames all overlap: none kept
  EXPECT_EQ(dropped.exit_code, expected_exit(tmp / "drop")) << dropped.err;
  ASSERT_EQ(frames(tmp / "flag", {"--overlap", "flag"}).exit_code, 0);
  const json drop = read_json(tmp / "drop/manifest.json")["counts"];
  const json flag = read_json(tmp / "flag/manifest.json")["counts"];
  const json keep = read_json(kept_export() / "manifest.json")["counts"];
  EXPECT_EQ(sum(drop["frames"]) + drop["dropped"]["overlap"].get<int64_t>(), sum(keep["frames"]));
  EXPECT_EQ(flag["flagged_overlap"], drop["dropped"]["overlap"]);
  EXPECT_EQ(sum(flag["frames"]), sum(keep["frames"]));
  int64_t marked = 0;
  for (const json& r : records(tmp / "flag")) marked += r.at("overlap").get<bool>() ? 1 : 0;
  EXPECT_EQ(marked, flag["flagged_overlap"].get<int64_t>());
  for (const json& r : records(tmp / "drop")) EXPECT_FALSE(r.contains("overlap"));
}

TEST(FramesExport, TheSameInputsGiveTheSameBytesAndAnExportIsNotOverwrittenUnasked) {
  TempDir tmp("frames-again");
  ASSERT_EQ(frames(tmp / "out", {"--overlap", "keep"}).exit_code, 0);
  EXPECT_EQ(read_json(tmp / "out/manifest.json")["files"], read_json(kept_export() / "manifest.json")["files"]);
  const CommandResult again = frames(tmp / "out", {"--overlap", "keep"});
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("--overwrite"), std::string::npos) << again.err;
  const CommandResult replaced = frames(tmp / "out", {"--overwrite"});
  ASSERT_EQ(replaced.exit_code, expected_exit(tmp / "out")) << replaced.err;
  // --overwrite replaces a frames export only, never a dataset given as --out by mistake
  // (a copy of the dataset's manifest stands for it here).
  const std::string dataset_manifest = read_text(e2e_dataset() / "manifest.json");
  write_text(tmp / "dataset-like/manifest.json", dataset_manifest);
  const CommandResult wrong = run_nsgraph({"frames", "--quiet", "--dataset", e2e_dataset().string(), "--out",
                                           (tmp / "dataset-like").string(), "--overwrite"});
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_NE(wrong.err.find("is not one"), std::string::npos) << wrong.err;
  EXPECT_EQ(read_text(tmp / "dataset-like/manifest.json"), dataset_manifest);
  // The overlapping frames of the first run are gone with it.
  const json counts = read_json(tmp / "out/manifest.json")["counts"];
  int64_t on_disk = 0;
  for (const auto& e : fs::recursive_directory_iterator(tmp / "out"))
    on_disk += e.is_regular_file() && e.path().parent_path().filename() == "info";
  EXPECT_EQ(on_disk, sum(counts["frames"]));
}

// --overwrite removes only the files the earlier export's manifest lists: a user's file
// in a split folder, or a folder with split folders and no manifest (a decoy), is named
// and the run refused before anything is removed; --out is never the dataset.
TEST(FramesExport, OverwriteRemovesOnlyTheListedFilesAndOutIsNoInput) {
  TempDir tmp("frames-own");
  ASSERT_EQ(frames(tmp / "out", {"--overlap", "keep"}).exit_code, 0);
  write_text(tmp / "out" / "test" / "my-notes.txt", "the user's");
  const std::string manifest = read_text(tmp / "out" / "manifest.json");
  CommandResult r = frames(tmp / "out", {"--overlap", "keep", "--overwrite"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("test/my-notes.txt"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(tmp / "out" / "test" / "my-notes.txt"), "the user's");
  EXPECT_EQ(read_text(tmp / "out" / "manifest.json"), manifest);

  write_text(tmp / "decoy" / "train" / "scene-x" / "info" / "1.json", "{}");
  for (const std::vector<std::string>& extra : {std::vector<std::string>{}, {"--overwrite"}}) {
    r = frames(tmp / "decoy", extra);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("train/scene-x/info/1.json"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(tmp / "decoy" / "train" / "scene-x" / "info" / "1.json"));
  }

  const fs::path dataset = tmp / "dataset";
  fs::copy(e2e_dataset(), dataset, fs::copy_options::recursive);
  r = run_nsgraph({"frames", "--quiet", "--dataset", dataset.string(), "--out", dataset.string(), "--dataroot",
                   e2e_release().string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--dataset"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dataset / "data_dict.json"));
}

// An export that keeps no frame says why (the counts by reason and the option that keeps
// them) and exits 1, like generate's empty run; the manifest still records the counts.
TEST(FramesExport, NoFrameKeptIsAFailedRunThatSaysWhy) {
  TempDir tmp("frames-empty");
  const CommandResult r = run_nsgraph({"frames", "--dataset", e2e_dataset().string(), "--out", (tmp / "out").string(),
                                       "--set", "window.x_min_m=-200", "--set", "window.x_max_m=200", "--set",
                                       "window.y_min_m=-200", "--set", "window.y_max_m=200"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("no frame kept"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--overlap keep"), std::string::npos) << r.err;
  const json counts = read_json(tmp / "out" / "manifest.json")["counts"];
  EXPECT_EQ(sum(counts["frames"]), 0);
  EXPECT_GT(counts["dropped"]["overlap"].get<int64_t>(), 0);
}

// A scene name from the release becomes the record's folder (segment_id): one named like
// a path is refused by name (exit 2), and nothing is written outside --out.
TEST(FramesExport, ASceneNamedLikeAPathIsRefusedByName) {
  TempDir tmp("frames-escape");
  const json scenes = read_json(e2e_release() / kVersion / "scene.json");
  const std::string from = scenes[0]["name"];
  const fs::path view = release_with_renamed_scene(e2e_release(), kVersion, from, "../../escaped", tmp / "release");
  const CommandResult r = frames(tmp / "export" / "out", {"--overlap", "keep", "--dataroot", view.string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("../../escaped"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scene.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "escaped"));
  EXPECT_FALSE(fs::exists(tmp / "export" / "escaped"));
}

TEST(FramesExport, CopiedImagesLieBesideTheRecords) {
  TempDir tmp("frames-copy");
  const CommandResult r = frames(tmp / "out", {"--overlap", "keep", "--copy-images"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<json> all = records(tmp / "out");
  ASSERT_FALSE(all.empty());
  const json& first = all[0];
  const std::string prefix =
      first["split"].get<std::string>() + "/" + first["segment_id"].get<std::string>() + "/image/";
  for (const auto& [camera, cam] : first["sensor"].items()) {
    const std::string path = cam["image_path"];
    EXPECT_EQ(path, prefix + camera + "/" + std::to_string(first["timestamp"].get<int64_t>()) + ".jpg");
    ASSERT_TRUE(fs::exists(tmp / "out" / path)) << path;
  }
  const json manifest = read_json(tmp / "out/manifest.json");
  size_t images = 0;
  for (const json& r : all) images += r["sensor"].size();
  EXPECT_EQ(manifest["files"].size(), all.size() + images + 1);  // records, images and data_dict.json
}

TEST(FramesExport, BadInputIsRefusedByName) {
  TempDir tmp("frames-bad");
  const CommandResult typo = frames(tmp / "a", {"--set", "window.x_max=60"});
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.err.find("window.x_max_m"), std::string::npos) << typo.err;  // did you mean
  const CommandResult empty_window = frames(tmp / "b", {"--set", "window.x_min_m=50"});
  EXPECT_EQ(empty_window.exit_code, 2);
  EXPECT_NE(empty_window.err.find("window.x_max_m"), std::string::npos) << empty_window.err;
  const CommandResult mode = frames(tmp / "c", {"--overlap", "ignore"});
  EXPECT_EQ(mode.exit_code, 2);
  EXPECT_NE(mode.err.find("overlap"), std::string::npos) << mode.err;
  const CommandResult no_dataset =
      run_nsgraph({"frames", "--quiet", "--dataset", (tmp / "none").string(), "--out", (tmp / "d").string()});
  EXPECT_EQ(no_dataset.exit_code, 2);
  EXPECT_NE(no_dataset.err.find("manifest.json"), std::string::npos) << no_dataset.err;
  // A map that is not the one the dataset was built from: the frames' lanes would differ.
  const fs::path view = tmp / "release";
  fs::create_directories(view / "maps/expansion");
  for (const auto& e : fs::directory_iterator(e2e_release()))
    if (e.path().filename() != "maps") fs::create_symlink(e.path(), view / e.path().filename());
  for (const auto& e : fs::directory_iterator(e2e_release() / "maps"))
    if (e.path().filename() != "expansion") fs::create_symlink(e.path(), view / "maps" / e.path().filename());
  fs::copy_file(e2e_release() / "maps/expansion/boston-seaport.json", view / "maps/expansion/boston-seaport.json");
  std::ofstream(view / "maps/expansion/boston-seaport.json", std::ios::app) << "\n";
  const CommandResult moved = frames(tmp / "e", {"--dataroot", view.string()});
  EXPECT_EQ(moved.exit_code, 2);
  EXPECT_NE(moved.err.find("boston-seaport.json"), std::string::npos) << moved.err;
  EXPECT_NE(moved.err.find("sha256"), std::string::npos) << moved.err;
  EXPECT_FALSE(fs::exists(tmp / "e/manifest.json"));
}

// The records of `split` as an OpenLane-V2 results document: a perfect submission.
// A record's area as the scorer resamples the ground truth's (20 points, collect()'s rule).
json resampled(const json& points) {
  std::vector<metrics::Point3> line;
  for (const json& p : points) line.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
  json out = json::array();
  for (const metrics::Point3& p : metrics::interpolate_like_collect(line, metrics::kAreaPoints))
    out.push_back({p[0], p[1], p[2]});
  return out;
}

// The export's own annotation as OpenLane-V2 results: centerlines, and with
// `map_elements` also its lane segments and areas (the lane-segment track).
json copy_as_results(const fs::path& dir, const std::string& split, bool map_elements = false) {
  json results = json::object();
  double confidence = 0.999;
  for (const json& r : records(dir)) {
    if (r["split"] != split) continue;
    const json& a = r["annotation"];
    json lanes = json::array();
    for (const json& c : a["lane_centerline"]) {
      lanes.push_back({{"id", c["id"]}, {"points", c["points"]}, {"confidence", confidence}});
      confidence -= 1e-4;
    }
    json predictions = {{"lane_centerline", lanes}, {"topology_lclc", a["topology_lclc"]}};
    if (map_elements) {
      json segments = json::array(), areas = json::array();
      for (json s : a["lane_segment"]) {
        s["confidence"] = confidence;
        confidence -= 1e-4;
        segments.push_back(s);
      }
      for (const json& area : a["area"]) {
        areas.push_back({{"id", area["id"]},
                         {"category", area["category"]},
                         {"points", resampled(area["points"])},
                         {"confidence", confidence}});
        confidence -= 1e-4;
      }
      predictions["lane_segment"] = segments;
      predictions["area"] = areas;
      predictions["topology_lsls"] = a["topology_lsls"];
    }
    results[r["sample_token"].get<std::string>()] = {{"predictions", predictions}};
  }
  return {{"method", "copy"}, {"results", results}};
}

// The lane-segment track through the CLI: the export's own lane segments and areas score 1
// on DET_ls, DET_a and TOP_lsls; the evaluator's score is then (1 + 1 + 1 + 1 + 0) / 5, its
// DET_t being 1 and its TOP_lt 0 without traffic elements.
TEST(ScoreFrames, TheExportsOwnLaneSegmentsAndAreasScoreOne) {
  TempDir tmp("score-frames-ls");
  const fs::path& dir = kept_export();
  write_text(tmp / "copy.json", copy_as_results(dir, "test", true).dump());
  const CommandResult r = run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", dir.string(), "--submission",
                                       (tmp / "copy.json").string(), "--split", "test"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out);
  EXPECT_EQ(report["DET_l"], 1.0);
  const json& ls = report["lane_segments"];
  EXPECT_EQ(ls["DET_ls"], 1.0);
  EXPECT_EQ(ls["DET_a"], 1.0);
  EXPECT_EQ(ls["TOP_lsls"], 1.0);
  EXPECT_NEAR(ls["score"].get<double>(), 0.8, 1e-12);
  EXPECT_EQ(report["counts"]["gt_lane_segments"], report["counts"]["gt_centerlines"]);
  EXPECT_GT(report["counts"]["gt_areas"].get<int64_t>(), 0);
  const CommandResult md = run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", dir.string(), "--submission",
                                        (tmp / "copy.json").string(), "--split", "test", "--format", "md"});
  ASSERT_EQ(md.exit_code, 0) << md.err;
  EXPECT_NE(md.out.find("| DET_l |"), std::string::npos) << md.out;
  EXPECT_NE(md.out.find("| DET_ls | DET_a |"), std::string::npos) << md.out;
  EXPECT_NE(md.out.find("| 1.0000 | 1.0000 | 1.0000 | 1.0000 | 1.0000 | 0.8000 |"), std::string::npos) << md.out;
  // Without them, the centerline report has no lane-segment part.
  write_text(tmp / "lanes.json", copy_as_results(dir, "test").dump());
  const CommandResult lanes = run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", dir.string(),
                                           "--submission", (tmp / "lanes.json").string(), "--split", "test"});
  ASSERT_EQ(lanes.exit_code, 0) << lanes.err;
  EXPECT_TRUE(json::parse(lanes.out)["lane_segments"].is_null());
}

TEST(ScoreFrames, APerfectSubmissionScoresOneThroughTheExportsManifest) {
  TempDir tmp("score-frames");
  const fs::path& dir = kept_export();
  write_text(tmp / "copy.json", copy_as_results(dir, "test").dump());
  const CommandResult r =
      run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", dir.string(), "--submission",
                   (tmp / "copy.json").string(), "--split", "test", "--out", (tmp / "report.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out);
  EXPECT_EQ(report, read_json(tmp / "report.json"));
  EXPECT_EQ(report["DET_l"], 1.0);
  EXPECT_EQ(report["TOP_ll"], 1.0);
  EXPECT_EQ(report["lane_score"], 1.0);
  for (const auto& [name, value] : report["nsgraph_metrics"].items()) EXPECT_GT(value.get<double>(), 0.9999) << name;
  EXPECT_EQ(report["counts"]["frames"], read_json(dir / "manifest.json")["counts"]["frames"]["test"]);
  EXPECT_EQ(report["counts"]["missing_frames"], 0);
  // The train split's frames are other keys: all missing, nothing matched.
  const CommandResult train = run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", dir.string(),
                                           "--submission", (tmp / "copy.json").string(), "--split", "train"});
  ASSERT_EQ(train.exit_code, 0) << train.err;
  EXPECT_EQ(json::parse(train.out)["counts"]["missing_frames"], json::parse(train.out)["counts"]["frames"]);
  EXPECT_EQ(json::parse(train.out)["DET_l"], 0.0);
}

TEST(ScoreFrames, BadResultsExitOneAndATamperedRecordExitsTwo) {
  TempDir tmp("score-frames-bad");
  const fs::path& dir = kept_export();
  json bad = copy_as_results(dir, "test");
  bad["results"].begin().value()["predictions"]["topology_lclc"] = json::array();
  write_text(tmp / "bad.json", bad.dump());
  const CommandResult r = run_nsgraph(
      {"score", "--quiet", "--frames", "--ground-truth", dir.string(), "--submission", (tmp / "bad.json").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("frames.results.schema"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/predictions/topology_lclc"), std::string::npos) << r.err;
  // A record edited after the export: the manifest's sha256 names it.
  fs::copy(dir, tmp / "export", fs::copy_options::recursive);
  std::string victim;
  const json manifest = read_json(tmp / "export/manifest.json");
  for (const json& f : manifest["files"])
    if (f["path"].get<std::string>().rfind("test/", 0) == 0) victim = f["path"];
  ASSERT_FALSE(victim.empty());
  std::string text = read_text(tmp / "export" / victim);
  text[text.find("\"points\":[[") + 11] = text[text.find("\"points\":[[") + 11] == '1' ? '2' : '1';
  write_text(tmp / "export" / victim, text);
  write_text(tmp / "copy.json", copy_as_results(dir, "test").dump());
  const CommandResult t = run_nsgraph({"score", "--quiet", "--frames", "--ground-truth", (tmp / "export").string(),
                                       "--submission", (tmp / "copy.json").string()});
  EXPECT_EQ(t.exit_code, 2) << t.err;
  EXPECT_NE(t.err.find(victim), std::string::npos) << t.err;
  EXPECT_NE(t.err.find("sha256"), std::string::npos) << t.err;
}

TEST(FramesConfig, ListingSchemaAndSampleEqualTheDeclarations) {
  const CommandResult printed = run_nsgraph({"frames", "--print-config"});
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_EQ(json::parse(printed.out), read_json(source_dir() / "samples/frames.json"))
      << "make regen regenerates it: nsgraph frames --print-config > samples/frames.json";
  const CommandResult schema = run_nsgraph({"frames", "--list-options", "--format", "schema"});
  ASSERT_EQ(schema.exit_code, 0) << schema.err;
  EXPECT_EQ(json::parse(schema.out), read_json(source_dir() / "schemas/v1/frames-config.schema.json"))
      << "make regen regenerates it: nsgraph frames --list-options --format schema > "
         "schemas/v1/frames-config.schema.json";
  const CommandResult sample =
      run_nsgraph({"frames", "--config", (source_dir() / "samples/frames.json").string(), "--print-config"});
  EXPECT_EQ(sample.exit_code, 0) << sample.err;
}

}  // namespace
}  // namespace nsg::test
