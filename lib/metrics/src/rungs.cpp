#include "nsg/metrics/rungs.h"

#include <cmath>
#include <regex>

namespace nsg::metrics {

std::map<int, GraphSet> take_rung_tiles(const GraphSet& gt, GraphSet& pred) {
  static const std::regex kRungKey(R"((.+)-r([1-9][0-9]{0,5}))");
  std::map<int, GraphSet> out;
  for (auto it = pred.begin(); it != pred.end();) {
    std::smatch m;
    if (!gt.count(it->first) && std::regex_match(it->first, m, kRungKey) && gt.count(m[1].str())) {
      out[std::stoi(m[2].str())][m[1].str()] = std::move(it->second);
      it = pred.erase(it);
    } else {
      ++it;
    }
  }
  return out;
}

RungStat mean_and_se(const std::vector<double>& xs) {
  RungStat s;
  s.n = static_cast<int64_t>(xs.size());
  if (xs.empty()) return s;
  double sum = 0.0;
  for (double x : xs) sum += x;
  const double mean = sum / static_cast<double>(xs.size());
  s.mean = mean;
  if (xs.size() < 2) return s;
  double ss = 0.0;
  for (double x : xs) ss += (x - mean) * (x - mean);
  s.se = std::sqrt(ss / static_cast<double>(xs.size() - 1) / static_cast<double>(xs.size()));
  return s;
}

namespace {

std::map<std::string, const TileMeasurement*> by_key(const ScoreReport& r) {
  std::map<std::string, const TileMeasurement*> out;
  for (const TileMeasurement& t : r.tiles) out[t.key] = &t;
  return out;
}

// Metric `m` of `a` minus `b` over the tiles defined in both.
RungStat paired(const ScoreReport& a, const ScoreReport& b, int m) {
  const auto bk = by_key(b);
  std::vector<double> diffs;
  for (const TileMeasurement& t : a.tiles) {
    const auto it = bk.find(t.key);
    if (it != bk.end() && t.values[m] && it->second->values[m]) diffs.push_back(*t.values[m] - *it->second->values[m]);
  }
  return mean_and_se(diffs);
}

RungScore score_of(const std::string& name, const ScoreReport& r, const ScoreReport* previous, const ScoreReport* all) {
  RungScore s;
  s.rung = name;
  s.tiles = r.aggregate.n_tiles;
  s.missing = r.aggregate.n_missing_predictions;
  for (int m = 0; m < kMetricCount; ++m) {
    std::vector<double> xs;
    for (const TileMeasurement& t : r.tiles)
      if (t.values[m]) xs.push_back(*t.values[m]);
    s.metrics[m] = mean_and_se(xs);
    if (previous) s.vs_previous[m] = paired(r, *previous, m);
    if (all) s.vs_all[m] = paired(r, *all, m);
  }
  return s;
}

nlohmann::json stat_json(const RungStat& s) {
  const auto opt = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  return {{"mean", opt(s.mean)}, {"se", opt(s.se)}, {"n", s.n}};
}

nlohmann::json stats_json(const std::array<RungStat, kMetricCount>& stats) {
  nlohmann::json out = nlohmann::json::object();
  for (int m = 0; m < kMetricCount; ++m) out[metric_name(m)] = stat_json(stats[m]);
  return out;
}

}  // namespace

std::vector<RungScore> rung_scores(const std::map<int, ScoreReport>& rung_reports, const ScoreReport& all_report) {
  std::vector<RungScore> out;
  const ScoreReport* previous = nullptr;
  for (const auto& [rung, report] : rung_reports) {
    out.push_back(score_of(std::to_string(rung), report, previous, &all_report));
    previous = &report;
  }
  out.push_back(score_of("all", all_report, previous, nullptr));
  return out;
}

nlohmann::json rungs_to_json(const std::vector<RungScore>& rungs) {
  nlohmann::json out = nlohmann::json::array();
  for (const RungScore& r : rungs) {
    nlohmann::json j = {
        {"rung", r.rung}, {"tiles", r.tiles}, {"missing", r.missing}, {"metrics", stats_json(r.metrics)}};
    if (&r != &rungs.front()) j["vs_previous"] = stats_json(r.vs_previous);
    if (r.rung != "all") j["vs_all"] = stats_json(r.vs_all);
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace nsg::metrics
