#pragma once
// Scoring an observation ladder (generate --ladder; docs/metrics.md, "Per rung"): the
// submission's tiles grouped by rung — a key <tile>-r<k> is tile <tile> seen by k scenes,
// a key <tile> the tile seen by all — each rung scored against the same ground truth, with
// every metric's mean ± standard error over the tiles and the paired differences between
// rungs on the same tiles.
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nsg/metrics/graph.h"
#include "nsg/metrics/measure.h"
#include "nsg/metrics/score.h"

namespace nsg::metrics {

// A metric over a rung's tiles, or a paired difference over the tiles defined in both rungs.
struct RungStat {
  std::optional<double> mean, se;  // se: sample standard deviation / √n (undefined for n < 2)
  int64_t n = 0;
};

// Mean and standard error of `xs` (the report's paired differences use it too).
RungStat mean_and_se(const std::vector<double>& xs);

struct RungScore {
  std::string rung;  // "1", "2", …, "all"
  int64_t tiles = 0, missing = 0;
  std::array<RungStat, kMetricCount> metrics{};
  std::array<RungStat, kMetricCount> vs_previous{};  // this rung − the one before (none for the first)
  std::array<RungStat, kMetricCount> vs_all{};       // this rung − "all" (none for "all", or without it)
};

// The most rungs one submission may hold (each is a whole scoring of the split); a
// ladder is built with a handful (generate --ladder: 1, 2, 4, all).
inline constexpr size_t kMaxScoredRungs = 32;

// Moves the keys "<gt key>-r<k>" of `pred` into rung k under "<gt key>"; what stays in
// `pred` is the "all" rung. Empty when no key names a rung of a ground-truth tile.
std::map<int, GraphSet> take_rung_tiles(const GraphSet& gt, GraphSet& pred);

// The rungs in order (built rungs ascending, then "all" from `all_report`, the split tiles'
// report) with their statistics.
std::vector<RungScore> rung_scores(const std::map<int, ScoreReport>& rung_reports, const ScoreReport& all_report);

nlohmann::json rungs_to_json(const std::vector<RungScore>& rungs);

}  // namespace nsg::metrics
