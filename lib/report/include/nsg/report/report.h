#pragma once
// `nsgraph report`: a self-contained HTML folder to browse a dataset, or a submission
// scored against it. index.html with one JavaScript and one CSS file of our own (no
// network, opens from file://), data files it loads with <script> tags (browsers refuse
// fetch() from file://), and per-tile layer PNGs loaded on demand:
//   index.html report.js report.css report.json
//   data/summary.js  data/tiles.js  data/tile/<key>.js   img/<key>.<layer>.png
//   img/overview-<location>.png
// The folder is written under a temp name and renamed at the end: nothing half-written.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nsg/core/issues.h"

namespace nsg::report {

struct ReportOptions {
  std::string split;                 // "" = the submission's split (from its keys), every split without
  std::filesystem::path submission;  // "" = dataset report (stats per split, no scores)
  std::filesystem::path baseline;    // a second submission to compare with (needs submission)
  std::filesystem::path schemas;     // schemas folder ("" = installed/source)
  int threads = 1;                   // 0 = all cores; the bytes written do not depend on it
  int overview_max_px = 1600;        // longest side of a location's background image
  bool progress = false;             // a progress line over the tiles on stderr (the CLI's)
  void validate() const;             // throws ConfigError
};

struct ReportResult {
  // Problems of the submission or baseline (validate's checks): non-empty = no report
  // was written (the command exits 1, like `score`).
  Issues issues;
  std::string rejected;  // the file the issues are about
  int64_t tiles = 0;
  int64_t images = 0;
  int64_t images_reused = 0;  // of `images`: taken from the earlier report at `out` (tiles unchanged)
  int64_t bytes = 0;          // total size of the folder written
};

// Writes the report of `dataset` to `out`. `out` must not exist, or be an earlier report
// (it is replaced whole; the layer images of tiles whose bytes did not change are taken
// from it instead of being rendered again, kept apart by a fingerprint of the tile's
// members and of this build). Throws IoError / ParseError / DataError naming the file for bad
// inputs (unreadable dataset, missing shards, malformed tiles), ConfigError for options.
ReportResult write_report(const std::filesystem::path& dataset, const std::filesystem::path& out,
                          const ReportOptions& options);

// `nsgraph report --leaderboard`: an offline page ranking score reports. Reads every
// *.json in `reports` (a score report carrying its receipt, as `nsgraph score --out` writes
// it), keeps those whose numbers still hash to their receipt and whose receipt names the
// same ground truth (dataset manifest sha256 and split, or ground-truth file sha256) and
// metrics version as the first such report in name order, and writes `out`:
//   index.html leaderboard.js leaderboard.css leaderboard.json data/leaderboard.js
// (temp name, renamed). `out` must be new, empty or an earlier leaderboard.
struct LeaderboardResult {
  int64_t entries = 0;
  std::vector<std::string> rejected;  // "<file>: <reason>", also listed on the page
};
// Throws IoError when `reports` cannot be read, DataError when no report is accepted.
LeaderboardResult write_leaderboard(const std::filesystem::path& reports, const std::filesystem::path& out);

// Mean of the paired differences a − b over the entries where both are defined, and its
// standard error (sample standard deviation / √n; undefined for n < 2).
struct PairedDifference {
  int64_t n = 0;
  std::optional<double> mean, standard_error;
};
PairedDifference paired_difference(const std::vector<std::optional<double>>& a,
                                   const std::vector<std::optional<double>>& b);

}  // namespace nsg::report
