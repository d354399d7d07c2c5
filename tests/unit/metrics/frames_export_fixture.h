#pragma once
// A hand-made `nsgraph frames` export for the tests of its readers (frames_documents.h): a
// record as the writer writes it and a manifest listing files with their true sizes and
// sha256, so that a test breaks one field or one file and sees that defect named.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/sha256.h"
#include "test_support.h"

namespace nsg::test {

// One camera, two centerlines along x, the first linked to the second (frame.schema.json).
inline nlohmann::json frame_record_json(const std::string& token = "tok", const std::string& split = "test") {
  using nlohmann::json;
  const json eye = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  const json pose = {{"rotation", eye}, {"translation", {600.0, 1600.0, 0.0}}};
  json lanes = json::array();
  for (int k = 0; k < 2; ++k) {
    json points = json::array(), points_2m = json::array();
    for (int i = 0; i <= 10; ++i) points.push_back({-20.0 + 4.0 * i, 3.5 * k, 0.0});
    for (int i = 0; i <= 20; ++i) points_2m.push_back({-20.0 + 2.0 * i, 3.5 * k, 0.0});
    lanes.push_back({{"id", 1000 * k},
                     {"points", points},
                     {"points_2m", points_2m},
                     {"is_intersection_or_connector", k == 1},
                     {"lane_token", "lane-" + std::to_string(k)},
                     {"starts_at_lane_start", k == 1},
                     {"ends_at_lane_end", k == 0}});
  }
  const json camera = {
      {"image_path", "samples/CAM_FRONT/x.jpg"},
      {"timestamp", 1},
      {"width", 1600},
      {"height", 900},
      {"extrinsic", pose},
      {"intrinsic",
       {{"K", {{1266.4, 0.0, 816.3}, {0.0, 1266.4, 491.5}, {0.0, 0.0, 1.0}}}, {"distortion", json::array()}}},
      {"ego_pose", pose}};
  return {{"schema_version", "1"},
          {"version", "nsgraph-frames-1"},
          {"segment_id", "scene-0001"},
          {"meta_data",
           {{"source", "nuscenes"},
            {"source_id", "s"},
            {"version", "v1.0-mini"},
            {"location", "boston-seaport"},
            {"map_version", "1.3"},
            {"region", "r0"}}},
          {"timestamp", 1},
          {"sample_token", token},
          {"split", split},
          {"sensor", {{"CAM_FRONT", camera}}},
          {"pose", pose},
          {"annotation",
           {{"lane_centerline", lanes},
            {"traffic_element", json::array()},
            {"topology_lclc", {{0, 1}, {0, 0}}},
            {"topology_lcte", {json::array(), json::array()}}}}};
}

// The same frame as a version-2 record: each centerline's lane segment (lanelines 1.75 m to
// either side, the first solid on its left), a crossing and a road boundary.
inline nlohmann::json frame_record_v2_json(const std::string& token = "tok", const std::string& split = "test") {
  using nlohmann::json;
  json record = frame_record_json(token, split);
  record["version"] = "nsgraph-frames-2";
  json segments = json::array();
  for (const json& c : record["annotation"]["lane_centerline"]) {
    json left = json::array(), right = json::array();
    for (const json& p : c["points"]) {
      left.push_back({p[0], p[1].get<double>() + 1.75, p[2]});
      right.push_back({p[0], p[1].get<double>() - 1.75, p[2]});
    }
    segments.push_back({{"id", c["id"]},
                        {"centerline", c["points"]},
                        {"left_laneline", left},
                        {"left_laneline_type", c["id"] == 0 ? 1 : 0},
                        {"right_laneline", right},
                        {"right_laneline_type", 0},
                        {"is_intersection_or_connector", c["is_intersection_or_connector"]}});
  }
  json& a = record["annotation"];
  a["lane_segment"] = segments;
  a["area"] = {{{"id", 0},
                {"category", 1},
                {"points", {{5.0, -2.0, 0.0}, {9.0, -2.0, 0.0}, {9.0, 6.0, 0.0}, {5.0, 6.0, 0.0}, {5.0, -2.0, 0.0}}}},
               {{"id", 1000000000}, {"category", 2}, {"points", {{-50.0, 7.0, 0.0}, {50.0, 7.0, 0.0}}}}};
  a["topology_lsls"] = a["topology_lclc"];
  a["topology_lste"] = a["topology_lcte"];
  return record;
}

inline nlohmann::json frames_manifest_json() {
  using nlohmann::json;
  return {{"schema_version", "1"},
          {"kind", "nsgraph-frames"},
          {"tool_version", "test"},
          {"source",
           {{"dataset", "d"},
            {"dataset_manifest_sha256", std::string(64, '2')},
            {"dataroot", "release"},
            {"version", "v1.0-mini"},
            {"split_buffer_m", 10.0}}},
          {"config",
           {{"window", {{"x_min_m", -50.0}, {"x_max_m", 50.0}, {"y_min_m", -25.0}, {"y_max_m", 25.0}}},
            {"centerline_points", 11},
            {"copy_images", false}}},
          {"layout", {{"records", ""}, {"images", ""}, {"traffic_elements", ""}}},
          {"counts", json::object()},
          {"files", json::array()}};
}

// Writes each (path relative to `dir`, text) and a manifest.json (`manifest` with its files
// listed: path, bytes, sha256); returns the manifest written.
inline nlohmann::json write_frames_export(const std::filesystem::path& dir,
                                          const std::vector<std::pair<std::string, std::string>>& files,
                                          nlohmann::json manifest = frames_manifest_json()) {
  manifest["files"] = nlohmann::json::array();
  for (const auto& [path, text] : files) {
    std::filesystem::create_directories((dir / path).parent_path());
    write_text(dir / path, text);
    manifest["files"].push_back({{"path", path}, {"bytes", text.size()}, {"sha256", sha256_hex(text)}});
  }
  write_text(dir / "manifest.json", manifest.dump(1));
  return manifest;
}

// An export of one test record (`record`, the fixture's by default) at this path.
inline constexpr const char* kFixtureRecordPath = "test/scene-0001/info/1.json";
inline nlohmann::json write_one_record_export(const std::filesystem::path& dir,
                                              const nlohmann::json& record = frame_record_json()) {
  return write_frames_export(dir, {{kFixtureRecordPath, record.dump()}});
}

}  // namespace nsg::test
