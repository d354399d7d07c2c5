#pragma once
// A complete manifest.json around hand-made shard entries, for tests that build a small
// dataset by hand: the manifest's reader (io/manifest.h) requires every field generate
// writes, so a test states only the shards it is about.
#include <string>

#include <nlohmann/json.hpp>

namespace nsg::test {

// `shards`: entries with at least name, split and file (tar) or folder (folder layout); the
// missing location, tiles, keys, sha256 and bytes are filled with placeholders, and the
// counts follow the entries.
inline nlohmann::json complete_manifest(nlohmann::json shards, const std::string& layout = "tar") {
  nlohmann::json counts = {{"train", {{"tiles", 0}, {"shards", 0}}},
                           {"val", {{"tiles", 0}, {"shards", 0}}},
                           {"test", {{"tiles", 0}, {"shards", 0}}},
                           {"total_tiles", 0}};
  for (nlohmann::json& s : shards) {
    if (!s.contains("location")) s["location"] = "boston-seaport";
    if (!s.contains("tiles")) s["tiles"] = 0;
    for (const char* key : {"first_key", "last_key"})
      if (!s.contains(key)) s[key] = "";
    if (!s.contains("sha256")) s["sha256"] = std::string(64, '0');
    if (!s.contains("bytes")) s["bytes"] = 0;
    const std::string split = s["split"];
    counts[split]["tiles"] = counts[split]["tiles"].get<int64_t>() + s["tiles"].get<int64_t>();
    counts[split]["shards"] = counts[split]["shards"].get<int64_t>() + 1;
    counts["total_tiles"] = counts["total_tiles"].get<int64_t>() + s["tiles"].get<int64_t>();
  }
  return {
      {"schema_version", "1"},
      {"seed", 0},
      {"config", nlohmann::json::object()},
      {"inputs",
       {{"dataroot", "release"},
        {"version", "v1.0-mini"},
        {"tables", nlohmann::json::array()},
        {"map_expansion", nlohmann::json::object()},
        {"detections", nullptr}}},
      {"layout", layout},
      {"tile_format",
       {{"resolution_m", 0.2},
        {"size_px", 256},
        {"key_pattern", "<location>-<split>-<NNNNNN>"},
        {"files", {"lidar.tif", "rgb.tif", "semantic.tif", "vehicle.tif", "coverage.tif", "graph.json", "meta.json"}}}},
      {"locations", nlohmann::json::array()},
      {"counts", counts},
      {"shards", shards},
      {"maps", nlohmann::json::array()}};
}

}  // namespace nsg::test
