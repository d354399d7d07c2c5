#include "nsg/io/tile_meta.h"

#include <cmath>

#include "nsg/core/error.h"
#include "nsg/io/manifest.h"  // kMaxRung: one bound for the manifest and the tile

namespace nsg::io {

namespace {

using nlohmann::json;

const json& member(const json& obj, const char* name, const std::string& file, const std::string& at) {
  NSG_CHECK(obj.is_object() && obj.contains(name), ParseError, file, at + "/" + name,
            "a field '" + std::string(name) + "'");
  return obj[name];
}

std::string text(const json& obj, const char* name, const std::string& file, const std::string& at = "") {
  const json& v = member(obj, name, file, at);
  NSG_CHECK(v.is_string(), ParseError, file, at + "/" + name, "a string");
  return v.get<std::string>();
}

double number(const json& obj, const char* name, double lo, double hi, const std::string& file,
              const std::string& at = "") {
  const json& v = member(obj, name, file, at);
  NSG_CHECK(v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() >= lo && v.get<double>() <= hi,
            ParseError, file, at + "/" + name, "a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v.get<double>();
}

int64_t integer(const json& obj, const char* name, int64_t hi, const std::string& file, const std::string& at = "") {
  const json& v = member(obj, name, file, at);
  NSG_CHECK(v.is_number_unsigned() && v.get<uint64_t>() <= static_cast<uint64_t>(hi), ParseError, file, at + "/" + name,
            "an integer in [0, " + std::to_string(hi) + "]");
  return v.get<int64_t>();
}

std::vector<std::string> strings(const json& obj, const char* name, const std::string& file, const std::string& at) {
  const json& v = member(obj, name, file, at);
  NSG_CHECK(v.is_array(), ParseError, file, at + "/" + name, "an array of strings");
  std::vector<std::string> out;
  for (size_t i = 0; i < v.size(); ++i) {
    NSG_CHECK(v[i].is_string(), ParseError, file, at + "/" + name + "/" + std::to_string(i), "a string");
    out.push_back(v[i].get<std::string>());
  }
  return out;
}

TileRung tile_rung_from_json(const json& doc, size_t scenes, const std::string& file) {
  TileRung r;
  r.rung = static_cast<int>(integer(doc, "rung", kMaxRung, file, "/ladder"));
  NSG_CHECK(r.rung >= 1, ParseError, file, "/ladder/rung", "a scene count of at least 1");
  r.base_key = text(doc, "base_key", file, "/ladder");
  r.order = text(doc, "order", file, "/ladder");
  NSG_CHECK(r.order == "time" || r.order == "seeded", ParseError, file, "/ladder/order", "time or seeded");
  r.scenes_seen = integer(doc, "scenes_seen", kMaxRung, file, "/ladder");
  r.capture_dates = strings(doc, "capture_dates", file, "/ladder");
  NSG_CHECK(r.capture_dates.size() == scenes, ParseError, file, "/ladder/capture_dates",
            "one date per scene of /scenes (" + std::to_string(scenes) + ")");
  return r;
}

}  // namespace

std::array<double, 4> bounds_from_json(const json& b, const std::string& file, const std::string& path) {
  NSG_CHECK(b.is_array() && b.size() == 4, ParseError, file, path, "[x_west, y_south, x_east, y_north]");
  constexpr double kMapExtentM = 1e7;  // far beyond any city map; keeps cell indices small
  std::array<double, 4> out{};
  for (size_t i = 0; i < 4; ++i) {
    NSG_CHECK(b[i].is_number() && std::isfinite(b[i].get<double>()) && std::fabs(b[i].get<double>()) <= kMapExtentM,
              ParseError, file, path + "/" + std::to_string(i), "a finite coordinate within ±1e7 m");
    out[i] = b[i].get<double>();
  }
  NSG_CHECK(out[0] < out[2] && out[1] < out[3], ParseError, file, path, "x_west < x_east and y_south < y_north");
  return out;
}

TileMeta tile_meta_from_json(const json& doc, const std::string& file) {
  NSG_CHECK(doc.is_object(), ParseError, file, "", "a tile's meta.json object");
  TileMeta m;
  m.key = text(doc, "key", file);
  m.location = text(doc, "location", file);
  m.split = text(doc, "split", file);
  NSG_CHECK(m.split == "train" || m.split == "val" || m.split == "test", ParseError, file, "/split",
            "train, val or test, got '" + m.split + "'");
  if (doc.contains("region")) m.region = text(doc, "region", file);
  m.resolution_m = number(doc, "resolution_m", 1e-3, 100.0, file);
  m.size_px = static_cast<int>(integer(doc, "size_px", kMaxTileSizePx, file));
  NSG_CHECK(m.size_px >= 1, ParseError, file, "/size_px", "a tile side of at least 1 px");
  m.bounds_m = bounds_from_json(member(doc, "bounds_m", file, ""), file, "/bounds_m");
  const json& cov = member(doc, "coverage", file, "");
  m.coverage_lidar = number(cov, "lidar", 0.0, 1.0, file, "/coverage");
  m.coverage_rgb = number(cov, "rgb", 0.0, 1.0, file, "/coverage");
  m.coverage_semantic = number(cov, "semantic", 0.0, 1.0, file, "/coverage");
  const json& counts = member(doc, "counts", file, "");
  constexpr int64_t kMaxCount = int64_t{1} << 40;
  m.nodes = integer(counts, "nodes", kMaxCount, file, "/counts");
  m.edges = integer(counts, "edges", kMaxCount, file, "/counts");
  m.vehicle_px = integer(counts, "vehicle_px", int64_t{m.size_px} * m.size_px, file, "/counts");
  if (doc.contains("scenes")) {
    const json& s = doc["scenes"];
    NSG_CHECK(s.is_array(), ParseError, file, "/scenes", "an array of scene names");
    for (size_t i = 0; i < s.size(); ++i) {
      NSG_CHECK(s[i].is_string(), ParseError, file, "/scenes/" + std::to_string(i), "a scene name");
      m.scenes.push_back(s[i].get<std::string>());
    }
  }
  if (doc.contains("ladder")) m.ladder = tile_rung_from_json(doc["ladder"], m.scenes.size(), file);
  return m;
}

nlohmann::ordered_json tile_meta_to_json(const TileMeta& m) {
  nlohmann::ordered_json doc = {
      {"schema_version", "1"},
      {"key", m.key},
      {"location", m.location},
      {"split", m.split},
      {"region", m.region},
      {"bounds_m", m.bounds_m},
      {"resolution_m", m.resolution_m},
      {"size_px", m.size_px},
      {"coverage", {{"lidar", m.coverage_lidar}, {"rgb", m.coverage_rgb}, {"semantic", m.coverage_semantic}}},
      {"counts", {{"nodes", m.nodes}, {"edges", m.edges}, {"vehicle_px", m.vehicle_px}}},
      {"scenes", m.scenes}};
  if (m.ladder)
    doc["ladder"] = {{"rung", m.ladder->rung},
                     {"base_key", m.ladder->base_key},
                     {"order", m.ladder->order},
                     {"scenes_seen", m.ladder->scenes_seen},
                     {"capture_dates", m.ladder->capture_dates}};
  return doc;
}

std::string tile_meta_text(const TileMeta& meta) { return tile_meta_to_json(meta).dump(2) + "\n"; }

}  // namespace nsg::io
