#pragma once
// A tile's <key>.meta.json (docs/dataset-format.md, schemas/v1/tile-meta.schema.json): its one
// writer (generate) and its one reader, with every field checked: `stats`, the report, the
// previews and the model trust nothing in a tile document they did not check (an empty
// bounds_m, a size_px of 20 000 or a resolution of 0 once crashed or hung them).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nsg::io {

// A ladder rung's tile (generate --ladder): the rung, the split tile it was rebuilt from, and
// the capture date of each of its scenes (TileMeta::scenes, same order).
struct TileRung {
  int rung = 1;  // scenes the rung allows; the tile uses min(rung, scenes_seen)
  std::string base_key;
  std::string order;        // "time" | "seeded"
  int64_t scenes_seen = 0;  // scenes whose sweeps the base tile holds
  std::vector<std::string> capture_dates;
};

struct TileMeta {
  std::string key, location, split, region;
  std::array<double, 4> bounds_m{};  // x_west, y_south, x_east, y_north; west < east, south < north
  double resolution_m = 0.2;
  int size_px = 256;
  double coverage_lidar = 0, coverage_rgb = 0, coverage_semantic = 0;  // fractions in [0, 1]
  int64_t nodes = 0, edges = 0, vehicle_px = 0;                        // vehicle_px <= size_px²
  std::vector<std::string> scenes;
  std::optional<TileRung> ladder;  // only in a rung tile
};

// [x_west, y_south, x_east, y_north] in metres, finite, within ±1e7 m, west < east and
// south < north: the one reader of a `bounds_m` (tile meta, manifest regions). ParseError
// naming `file` and `path` (e.g. "/bounds_m/2").
std::array<double, 4> bounds_from_json(const nlohmann::json& j, const std::string& file, const std::string& path);

// Largest tile side a reader accepts, in a tile's meta.json and in the manifest's
// tile_format: the format's crops are 256 px, and 4 096 is the largest a config may ask for
// (crops.size_px) and the largest GeoTIFF the decoder reads, while bounding every per-pixel
// loop a reader runs.
inline constexpr int kMaxTileSizePx = 4096;

// Throws ParseError naming `file` and the JSON path (e.g. "/bounds_m", "/counts/vehicle_px")
// for a missing field, a wrong type, a non-finite number or a value out of its range.
TileMeta tile_meta_from_json(const nlohmann::json& doc, const std::string& file);

// The document generate writes: fields in the schema's order, `region` always present;
// tile_meta_text is its bytes (2-space indent, a final newline). Reading the text back
// gives `meta` again.
nlohmann::ordered_json tile_meta_to_json(const TileMeta& meta);
std::string tile_meta_text(const TileMeta& meta);

}  // namespace nsg::io
