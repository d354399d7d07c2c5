#pragma once
// Pieces of the report builder (private to lib/report).
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"
#include "nsg/io/dataset.h"
#include "nsg/metrics/graph.h"
#include "nsg/metrics/score.h"
#include "nsg/report/report.h"

namespace nsg::report::detail {

// --- tile_pages.cpp: one pass over the tiles of the report.
struct TileInputs {
  const metrics::GraphSet* prediction = nullptr;  // null = dataset report
  const metrics::ScoreReport* scores = nullptr;
  const metrics::ScoreReport* baseline = nullptr;
  const metrics::GraphSet* baseline_prediction = nullptr;  // the baseline's graphs (overlay)
  // The submission's observation-ladder rungs, each rung's tiles under their ground-truth
  // keys (ScoredSubmission::rung_reports); null or empty without rung keys.
  const std::map<int, metrics::ScoreReport>* rung_scores = nullptr;
};
// The layer images of an earlier report that a rerun may take instead of rendering them:
// img/<key>.<layer>.png of tiles whose fingerprint (tile_fingerprint) is unchanged.
struct EarlierImages {
  std::filesystem::path dir;                        // the earlier report's folder ("" = none)
  std::map<std::string, std::string> fingerprints;  // key → fingerprint, from its kFingerprints
};
inline constexpr const char* kFingerprints = "img/fingerprints.json";
// Reads `report`'s kFingerprints; an empty set when it has none or it is unreadable (a
// rerun then renders every tile).
EarlierImages earlier_images(const std::filesystem::path& report);
struct TileRow {
  std::string key, location, split;
  std::vector<double> bounds_m;                         // x_west, y_south, x_east, y_north
  std::map<std::string, std::optional<double>> values;  // the per-tile table's columns
};
struct TilePass {
  std::vector<TileRow> rows;  // manifest order
  int64_t images = 0;
  int64_t images_reused = 0;  // of `images`, taken from the earlier report
};
// Writes img/<key>.<layer>.png, data/tile/<key>.js and kFingerprints under `dir` for every
// tile of `split` ("" = all), taking unchanged tiles' images from `earlier`; returns the
// table rows. A dataset with an observation ladder adds its rung tiles' images
// (img/<key>-r<k>.<layer>.png) and, in each split tile's data file, its rungs: what each saw
// and, when the submission predicts the rung key, that prediction marked and scored. Rung
// tiles are not table rows. `progress`: a progress line on stderr.
TilePass write_tile_pages(const io::Dataset& dataset, const std::string& split, const TileInputs& inputs,
                          const EarlierImages& earlier, const std::filesystem::path& dir, int threads, bool progress);
// The per-tile table's columns in display order (metrics first, then diagnostics).
std::vector<std::string> table_columns(bool submission, bool baseline);
// The columns whose smaller values are better (the metrics' metric_info, then the counts).
std::vector<std::string> lower_is_better_columns();

// --- summary.cpp
// data/summary.js's document: mode, summary table, locations with regions and buffers,
// legends, the main metrics.
nlohmann::ordered_json summary_document(const io::Dataset& dataset, const std::string& split,
                                        const metrics::ScoreReport* scores, const metrics::ScoreReport* baseline);
// data/tiles.js's document: columns of the per-tile table.
nlohmann::ordered_json tiles_document(const std::vector<TileRow>& rows, const std::vector<std::string>& columns);
// Writes img/overview-<location>.png per location with tiles; returns {location: georef}.
nlohmann::ordered_json write_overviews(const io::Dataset& dataset, const std::string& split,
                                       const std::vector<TileRow>& rows, const std::filesystem::path& dir, int max_px);

// --- report.cpp: writing a page's folder under a temp name.
void write_text(const std::filesystem::path& path, std::string_view text);  // IoError when it fails
int64_t folder_bytes(const std::filesystem::path& dir);
// Removes the temp folder unless the page was committed.
struct TempFolder {
  std::filesystem::path path;
  bool keep = false;
  ~TempFolder() {
    std::error_code ec;
    if (!keep) std::filesystem::remove_all(path, ec);
  }
};
// A page's folder is ours when its marker (report.json, leaderboard.json) lists every file
// in it (`files`); only then may a later run replace it.
// Writes the marker `doc` into `dir` with `files`: every file `dir` holds, and the marker.
void write_marker(const std::filesystem::path& dir, const char* marker, nlohmann::ordered_json doc);
// ConfigError naming `option` unless `out` is new, empty, or a page of ours (its marker
// lists every file in it: a user's file in there is named and refused, nothing removed).
void check_replaceable(const std::filesystem::path& out, const char* marker, const std::string& option);
// Puts `tmp` where `out` is: an earlier page (checked by check_replaceable) is moved aside
// first and removed after.
void replace_folder(const std::filesystem::path& tmp, const std::filesystem::path& out, const char* marker);

// --- assets (generated from lib/report/assets at build time)
// The leaderboard page's assets are named "leaderboard/<file>"; the report's are the others.
inline constexpr const char* kLeaderboardAssets = "leaderboard/";
struct Asset {
  const char* name;
  std::string_view bytes;
};
const std::vector<Asset>& assets();

// `NSG.receive("<name>", JSON.parse('<json>'));` — how the page loads data from file://.
std::string data_script(const std::string& name, const std::string& json_text);
// A value rounded to 6 decimals for the page (null when undefined).
nlohmann::json rounded(const std::optional<double>& v);

}  // namespace nsg::report::detail
