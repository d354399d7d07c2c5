#include "nsg/metrics/score.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <sstream>

#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/strings.h"

namespace nsg::metrics {
namespace {

nlohmann::json optional_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string md_value(const std::optional<double>& v, int decimals = 4) {
  return v ? strprintf("%.*f", decimals, *v) : std::string("—");
}

}  // namespace

void ScoreOptions::validate() const {
  params.validate();
  NSG_CHECK(threads >= 0 && threads <= 1024, ConfigError, "", "threads", "0 (all cores) or a thread count up to 1024");
  NSG_CHECK(std::isfinite(max_seconds) && max_seconds >= 0, ConfigError, "", "--max-seconds",
            "0 (no limit) or a number of seconds");
}

ScoreReport score(const GraphSet& gt, const GraphSet& pred, const ScoreOptions& options) {
  options.validate();
  ScoreReport report;
  report.params = options.params;
  std::vector<const std::string*> keys;
  for (const auto& [key, graph] : gt) {
    keys.push_back(&key);
    if (pred.find(key) == pred.end()) report.missing_tiles.push_back(key);
  }
  for (const auto& [key, graph] : pred)
    if (gt.find(key) == gt.end()) report.extra_tiles.push_back(key);

  // Each tile writes its own slot; the reduction below runs in key order, so the report
  // is identical for every thread count.
  report.tiles.resize(keys.size());
  const auto start = std::chrono::steady_clock::now();
  std::atomic<bool> over_time{false};
  std::atomic<int64_t> scored{0};
  // Tiles beyond the search work limit, reported in key order whichever thread met them.
  std::vector<std::optional<SearchWorkExceeded>> over_work(keys.size());
  Progress bar("score tiles", keys.size(), options.progress);
  parallel_for(keys.size(), options.threads, [&](size_t k) {
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    if (over_time || (options.max_seconds > 0 && elapsed.count() >= options.max_seconds)) {
      over_time = true;
      return;
    }
    const std::string& key = *keys[k];
    const auto p = pred.find(key);
    try {
      report.tiles[k] = measure(key, gt.at(key), p == pred.end() ? nullptr : &p->second, options.params);
      log::debug(strprintf("score: %s: search work %lld units", printable_text(key).c_str(),
                           static_cast<long long>(report.tiles[k].search_work)));
    } catch (const SearchWorkExceeded& e) {
      over_work[k] = e;
    }
    ++scored;
    bar.advance();
  });
  bar.finish();
  NSG_CHECK(!over_time, ConfigError, "", "--max-seconds",
            strprintf("a run that scores its %zu tiles within %g s (%lld scored when the budget ran out); raise "
                      "--max-seconds, or 0 for no limit",
                      keys.size(), options.max_seconds, static_cast<long long>(scored.load())));
  const auto first_over = std::find_if(over_work.begin(), over_work.end(), [](const auto& e) { return e.has_value(); });
  if (first_over != over_work.end()) {
    const auto more = std::count_if(first_over + 1, over_work.end(), [](const auto& e) { return e.has_value(); });
    throw SearchWorkExceeded(
        (*first_over)->file(), (*first_over)->record(),
        (*first_over)->expected() +
            (more > 0 ? strprintf(" (%lld more tiles are beyond it)", static_cast<long long>(more)) : std::string()));
  }
  Aggregate agg;
  for (const TileMeasurement& t : report.tiles) agg.add(t);
  agg.n_extra_predictions = static_cast<int64_t>(report.extra_tiles.size());
  report.aggregate = finalize(agg);
  return report;
}

nlohmann::json measurement_to_json(const TileMeasurement& tile) {
  nlohmann::json j = nlohmann::json::object();
  for (int m = 0; m < kMetricCount; ++m) j[metric_name(m)] = optional_json(tile.values[m]);
  nlohmann::json counts = nlohmann::json::object();
  for (int c = 0; c < kCountCount; ++c) counts[count_name(c)] = tile.counts[c];
  j["counts"] = std::move(counts);
  return j;
}

nlohmann::json aggregate_to_json(const AggregateReport& a) {
  nlohmann::json mean = nlohmann::json::object(), defined = nlohmann::json::object(),
                 undefined = nlohmann::json::object(), sums = nlohmann::json::object();
  for (int m = 0; m < kMetricCount; ++m) {
    mean[metric_name(m)] = optional_json(a.mean[m]);
    defined[metric_name(m)] = a.n_defined[m];
    undefined[metric_name(m)] = a.n_undefined[m];
  }
  for (int c = 0; c < kCountCount; ++c) sums[count_name(c)] = a.sums[c];
  nlohmann::json pooled = nlohmann::json::object();
  for (const auto& [name, value] : pooled_values(a)) pooled[name] = optional_json(value);
  return {{"n_tiles", a.n_tiles},
          {"n_missing_predictions", a.n_missing_predictions},
          {"n_extra_predictions", a.n_extra_predictions},
          {"mean", mean},
          {"n_defined", defined},
          {"n_undefined", undefined},
          {"pooled", pooled},
          {"sums", sums}};
}

nlohmann::json report_to_json(const ScoreReport& r) {
  nlohmann::json tiles = nlohmann::json::object();
  for (const TileMeasurement& t : r.tiles) tiles[t.key] = measurement_to_json(t);
  nlohmann::json out = {{"schema_version", "1"},
                        {"metrics_version", kMetricsVersion},
                        {"params", r.params.to_json()},
                        {"ground_truth", r.ground_truth},
                        {"submission", r.submission},
                        {"split", r.split},
                        {"ground_truth_verification", r.ground_truth_verification},
                        {"missing_tiles", r.missing_tiles},
                        {"extra_tiles", r.extra_tiles},
                        {"tiles", tiles},
                        {"aggregate", aggregate_to_json(r.aggregate)}};
  if (!r.receipt.is_null()) out["receipt"] = r.receipt;
  if (!r.rungs.is_null()) out["rungs"] = r.rungs;
  return out;
}

namespace {

// "mean ± se" of a rung statistic as rungs_to_json writes it ("—" when undefined).
std::string md_stat(const nlohmann::json& stat, int digits) {
  if (!stat.is_object() || !stat.value("mean", nlohmann::json()).is_number()) return "—";
  std::string text = md_value(stat["mean"].get<double>(), digits);
  if (stat.value("se", nlohmann::json()).is_number()) text += " ± " + md_value(stat["se"].get<double>(), digits);
  return text;
}

// The observation ladder's table (one row per rung: the headline metrics' mean ± s.e. over
// the rung's tiles, and APLS's paired difference from "all"); "" without rungs.
std::string rungs_markdown(const nlohmann::json& rungs) {
  if (!rungs.is_array() || rungs.empty()) return "";
  std::ostringstream out;
  out << "\nPer rung of the observation ladder (mean ± standard error over the rung's tiles; Δ APLS: paired "
         "difference from \"all\" on the same tiles):\n\n| rung | tiles | missing |";
  for (const HeadlineMetric& h : headline_metrics()) out << " " << h.label << " |";
  out << " Δ APLS vs all |\n|---|---:|---:|";
  for (size_t k = 0; k < headline_metrics().size(); ++k) out << "---:|";
  out << "---:|\n";
  for (const nlohmann::json& r : rungs) {
    out << "| " << r.value("rung", "?") << " | " << r.value("tiles", 0) << " | " << r.value("missing", 0) << " |";
    for (const HeadlineMetric& h : headline_metrics())
      out << " " << md_stat(r["metrics"].value(metric_name(h.metric), nlohmann::json()), h.digits) << " |";
    const nlohmann::json vs_all = r.value("vs_all", nlohmann::json::object());
    out << " " << md_stat(vs_all.value(metric_name(kApls), nlohmann::json()), 4) << " |\n";
  }
  return out.str();
}

}  // namespace

std::string report_to_markdown(const ScoreReport& r) {
  const AggregateReport& a = r.aggregate;
  std::ostringstream out;
  // The headline leaves out the summed Chamfer (m²: it grows with a tile's nodes); the
  // table of every metric below keeps it.
  std::string head = "|", rule = "|", values = "|";
  for (const HeadlineMetric& h : headline_metrics()) {
    head.append(" ").append(h.label).append(metric_info(h.metric).lower_is_better ? " ↓ |" : " ↑ |");
    rule += "---:|";
    values.append(" ").append(md_value(a.mean[h.metric], h.digits)).append(" |");
  }
  out << head << "\n" << rule << "\n" << values << "\n\n";
  out << "Macro means over " << a.n_tiles << " tiles (metrics v" << kMetricsVersion << "); " << a.n_missing_predictions
      << " missing predictions scored as empty, " << a.n_extra_predictions << " extra keys ignored. Pooled: F1 "
      << md_value(a.pooled_f1) << ", IoU " << md_value(a.pooled_iou) << ", GEO P/R/F1 "
      << md_value(a.pooled_geo_precision) << " / " << md_value(a.pooled_geo_recall) << " / "
      << md_value(a.pooled_geo_f1) << ".";
  // A map-update ground truth (its tiles have a prior graph): the change values pooled too.
  if (a.n_defined[kFalseChangeRate] > 0)
    out << " Map change: recall " << md_value(a.pooled_change_recall) << ", precision "
        << md_value(a.pooled_change_precision) << ", false-change rate " << md_value(a.pooled_false_change_rate) << ".";
  out << "\n\n";
  out << "| metric | mean | defined | undefined |\n|---|---:|---:|---:|\n";
  for (int m = 0; m < kMetricCount; ++m)
    out << "| `" << metric_name(m) << "` | " << md_value(a.mean[m], 6) << " | " << a.n_defined[m] << " | "
        << a.n_undefined[m] << " |\n";
  out << rungs_markdown(r.rungs);
  return out.str();
}

std::string report_to_csv(const ScoreReport& r) {
  std::ostringstream out;
  out << "key";
  for (int m = 0; m < kMetricCount; ++m) out << ',' << metric_name(m);
  for (int c = 0; c < kCountCount; ++c) out << ',' << count_name(c);
  out << '\n';
  for (const TileMeasurement& t : r.tiles) {
    out << t.key;  // keys have no commas or quotes (docs/dataset-format.md)
    for (int m = 0; m < kMetricCount; ++m) out << ',' << (t.values[m] ? format_double(*t.values[m]) : "");
    for (int c = 0; c < kCountCount; ++c) out << ',' << t.counts[c];
    out << '\n';
  }
  return out.str();
}

}  // namespace nsg::metrics
