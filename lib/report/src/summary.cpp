// The report's documents: the summary (mode, summary table with the baseline's paired
// differences, or the dataset's figures per split; locations with split regions and
// buffers; legends) and the per-tile table, plus the per-location background images.
#include <cmath>
#include <set>

#include "internal.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/coverage_bits.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/core/version.h"
#include "nsg/io/manifest.h"
#include "nsg/io/stats.h"
#include "nsg/metrics/rungs.h"
#include "nsg/preview/preview.h"

namespace nsg::report {

PairedDifference paired_difference(const std::vector<std::optional<double>>& a,
                                   const std::vector<std::optional<double>>& b) {
  NSG_CHECK(a.size() == b.size(), InternalError, "", "paired_difference", "two lists of the same length");
  std::vector<double> d;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i] && b[i]) d.push_back(*a[i] - *b[i]);
  const metrics::RungStat s = metrics::mean_and_se(d);
  PairedDifference r;
  r.n = s.n;
  r.mean = s.mean;
  r.standard_error = s.se;
  return r;
}

namespace detail {
namespace {

namespace fs = std::filesystem;

std::string hex(preview::Rgb c) { return strprintf("#%02x%02x%02x", c.r, c.g, c.b); }

// The metrics the overview colours by and the histograms show (docs/metrics.md's headline set).
std::vector<std::string> main_metrics() {
  std::vector<std::string> out;
  for (const metrics::HeadlineMetric& h : metrics::headline_metrics()) out.push_back(metrics::metric_name(h.metric));
  return out;
}
const std::vector<std::string> kMainFigures = {"coverage_lidar", "coverage_rgb", "gt_edges", "lane_length_m"};

nlohmann::ordered_json legends() {
  nlohmann::ordered_json semantic = nlohmann::ordered_json::array();
  for (int c = 0; c < preview::kSemanticClassCount; ++c)
    semantic.push_back({{"label", preview::semantic_name(c)}, {"color", hex(preview::semantic_color(c))}});
  semantic.push_back({{"label", "no data"}, {"color", hex(preview::kNoData)}});
  nlohmann::ordered_json heading = nlohmann::ordered_json::array();
  for (int q = 0; q < 8; ++q)
    heading.push_back({{"label", strprintf("%.0f°", q * 45.0)}, {"color", hex(preview::heading_color(q / 8.0))}});
  heading.push_back({{"label", "no vehicle (LiDAR dimmed)"}, {"color", "#606060"}});
  nlohmann::ordered_json coverage = nlohmann::ordered_json::array();
  const char* names[] = {
      "",         "LiDAR only", "RGB only", "LiDAR + RGB", "semantics only", "LiDAR + semantics", "RGB + semantics",
      "all three"};
  static_assert(sizeof(names) / sizeof(names[0]) == kCoverageAll + 1, "a label per coverage value");
  for (int f = 1; f <= kCoverageAll; ++f)
    coverage.push_back({{"label", names[f]}, {"color", hex(preview::coverage_color(static_cast<uint8_t>(f)))}});
  coverage.push_back({{"label", "no data"}, {"color", hex(preview::kNoData)}});
  nlohmann::ordered_json lidar = {{{"label", "low intensity"}, {"color", "#404040"}},
                                  {{"label", "high intensity"}, {"color", "#ffffff"}},
                                  {{"label", "no data"}, {"color", hex(preview::kNoData)}}};
  nlohmann::ordered_json splits;
  for (const char* s : {"train", "val", "test"}) splits[s] = hex(preview::split_color(s));
  // The graph overlays' colours (preview.h declares them once; the page sets its styles from these).
  nlohmann::ordered_json overlay = nlohmann::ordered_json::array();
  for (const preview::OverlayColor& o : preview::overlay_colors())
    overlay.push_back({{"name", o.name}, {"label", o.label}, {"color", hex(o.color)}, {"dashed", o.dashed}});
  return {{"lidar", lidar},       {"rgb", nlohmann::ordered_json::array()},
          {"semantic", semantic}, {"vehicle", heading},
          {"coverage", coverage}, {"splits", splits},
          {"overlay", overlay},   {"casing", hex(preview::kOverlayCasing)}};
}

// The manifest's region records, keys sorted (bounds_m, name, split) as the page has always
// had them.
nlohmann::json regions_json(const std::vector<io::Region>& regions) {
  nlohmann::json out = nlohmann::json::array();
  for (const io::Region& r : regions) out.push_back(nlohmann::json(io::region_to_json(r)));
  return out;
}

// The summary table of a scored submission (and of the baseline, with paired differences).
// The headline metrics first, by the names a leaderboard gives them, then every other one.
std::vector<std::pair<int, const char*>> summary_order() {
  std::vector<std::pair<int, const char*>> order;
  std::vector<bool> listed(metrics::kMetricCount, false);
  for (const metrics::HeadlineMetric& h : metrics::headline_metrics()) {
    order.emplace_back(h.metric, h.label);
    listed[h.metric] = true;
  }
  for (int m = 0; m < metrics::kMetricCount; ++m)
    if (!listed[m]) order.emplace_back(m, nullptr);
  return order;
}

nlohmann::ordered_json score_rows(const metrics::ScoreReport& s, const metrics::ScoreReport* base) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const auto& [m, label] : summary_order()) {
    nlohmann::ordered_json row = {{"metric", metrics::metric_name(m)},
                                  {"label", label ? nlohmann::ordered_json(label) : nlohmann::ordered_json(nullptr)},
                                  {"mean", rounded(s.aggregate.mean[m])},
                                  {"n_defined", s.aggregate.n_defined[m]},
                                  {"n_undefined", s.aggregate.n_undefined[m]}};
    if (base) {
      std::vector<std::optional<double>> a, b;
      for (size_t i = 0; i < s.tiles.size(); ++i) {
        NSG_CHECK(base->tiles[i].key == s.tiles[i].key, InternalError, "", s.tiles[i].key,
                  "the baseline scored on the same tiles");
        a.push_back(s.tiles[i].values[m]);
        b.push_back(base->tiles[i].values[m]);
      }
      const PairedDifference d = paired_difference(a, b);
      const auto& bm = base->aggregate.mean[m];
      row["baseline_mean"] = rounded(bm);
      row["difference"] =
          rounded(s.aggregate.mean[m] && bm ? std::optional<double>(*s.aggregate.mean[m] - *bm) : std::nullopt);
      row["paired_n"] = d.n;
      row["paired_mean"] = rounded(d.mean);
      row["paired_se"] = rounded(d.standard_error);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

nlohmann::ordered_json score_facts(const metrics::ScoreReport& s) {
  const auto& a = s.aggregate;
  nlohmann::ordered_json pooled = nlohmann::ordered_json::object();
  for (const auto& [name, value] : metrics::pooled_values(a)) pooled[name] = rounded(value);
  return {{"submission", s.submission},
          {"n_tiles", a.n_tiles},
          {"n_missing_predictions", a.n_missing_predictions},
          {"n_extra_predictions", a.n_extra_predictions},
          {"missing_tiles", s.missing_tiles},
          {"extra_tiles", s.extra_tiles},
          {"pooled", pooled},
          {"params", s.params.to_json()}};
}

}  // namespace

nlohmann::json rounded(const std::optional<double>& v) {
  if (!v || !std::isfinite(*v)) return nullptr;
  return std::round(*v * 1e6) / 1e6;
}

std::string data_script(const std::string& name, const std::string& json_text) {
  // JSON.parse of a string literal: browsers parse it faster than the same text as an
  // object literal (a 5 MB table of 20 000 tiles: 1.7–3.8 s instead of 4.1–5.2 s to load
  // in headless Chromium on a busy 2-core machine).
  std::string quoted;
  quoted.reserve(json_text.size() + json_text.size() / 16);
  for (const char c : json_text) {
    if (c == '\\' || c == '\'') quoted += '\\';
    quoted += c;
  }
  return "NSG.receive(" + nlohmann::json(name).dump() + ", JSON.parse('" + quoted + "'));\n";
}

nlohmann::ordered_json summary_document(const io::Dataset& dataset, const std::string& split,
                                        const metrics::ScoreReport* scores, const metrics::ScoreReport* baseline) {
  const std::string manifest = dataset.manifest_file();
  nlohmann::ordered_json doc;
  doc["format"] = "nsgraph-report-1";
  doc["tool"] = std::string("nsgraph ") + kVersion;
  doc["mode"] = scores ? "submission" : "dataset";
  doc["dataset"] = dataset.root().filename().empty() ? dataset.root().parent_path().filename().string()
                                                     : dataset.root().filename().string();
  doc["split"] = split;
  doc["layers"] = std::vector<std::string>(std::begin(preview::kTileLayerNames), std::end(preview::kTileLayerNames));
  doc["legends"] = legends();
  doc["columns"] = table_columns(scores != nullptr, baseline != nullptr);
  doc["main"] = scores ? main_metrics() : kMainFigures;
  doc["lower_is_better"] = lower_is_better_columns();
  if (scores) {
    doc["score"] = score_facts(*scores);
    if (baseline) doc["baseline"] = score_facts(*baseline);
    doc["summary"] = score_rows(*scores, baseline);
    if (!scores->rungs.is_null()) doc["rungs"] = scores->rungs;
  } else {
    doc["stats"] = io::stats_json(io::compute_stats(dataset.root()));
  }
  // The config is kept as written (pipeline reads it); the page shows only its buffer.
  const nlohmann::ordered_json& config = dataset.manifest().config;
  const nlohmann::ordered_json::json_pointer buffer_ptr("/splits/buffer_m");
  double buffer_m = 0.0;
  if (config.contains(buffer_ptr)) {
    const nlohmann::ordered_json& b = config.at(buffer_ptr);
    NSG_CHECK(b.is_number() && std::isfinite(b.get<double>()) && b.get<double>() >= 0, ParseError, manifest,
              "/config/splits/buffer_m", "a buffer of at least 0 metres");
    buffer_m = b.get<double>();
  }
  nlohmann::ordered_json locations = nlohmann::ordered_json::array();
  for (const io::ManifestLocation& loc : dataset.manifest().locations)
    locations.push_back({{"name", loc.name}, {"regions", regions_json(loc.regions)}, {"buffer_m", buffer_m}});
  doc["locations"] = std::move(locations);
  return doc;
}

nlohmann::ordered_json tiles_document(const std::vector<TileRow>& rows, const std::vector<std::string>& columns) {
  nlohmann::ordered_json keys = nlohmann::ordered_json::array(), locs = nlohmann::ordered_json::array(),
                         splits = nlohmann::ordered_json::array(), bounds = nlohmann::ordered_json::array();
  nlohmann::ordered_json values;
  for (const std::string& c : columns) values[c] = nlohmann::ordered_json::array();
  for (const TileRow& r : rows) {
    keys.push_back(r.key);
    locs.push_back(r.location);
    splits.push_back(r.split);
    nlohmann::ordered_json b = nlohmann::ordered_json::array();
    for (double x : r.bounds_m) b.push_back(std::round(x * 100.0) / 100.0);
    bounds.push_back(std::move(b));
    for (const std::string& c : columns) {
      const auto v = r.values.find(c);
      const nlohmann::json x = v == r.values.end() ? nlohmann::json(nullptr) : rounded(v->second);
      if (x.is_null()) values[c].push_back(nullptr);
      else values[c].push_back(x.get<double>());
    }
  }
  return {{"keys", keys}, {"location", locs}, {"split", splits}, {"bounds_m", bounds}, {"values", values}};
}

nlohmann::ordered_json write_overviews(const io::Dataset& dataset, const std::string& split,
                                       const std::vector<TileRow>& rows, const fs::path& dir, int max_px) {
  std::set<std::string> locations;
  for (const TileRow& r : rows) locations.insert(r.location);
  nlohmann::ordered_json out;
  preview::OverviewOptions options;
  options.max_map_px = max_px;
  for (const std::string& location : locations) {
    const preview::Overview ov = preview::render_overview(dataset, location, split, options);
    const preview::Rect& r = ov.map_rect;
    preview::Image map;
    map.width = r.width;
    map.height = r.height;
    map.rgb.resize(static_cast<size_t>(r.width) * r.height * 3);
    for (int y = 0; y < r.height; ++y)
      std::copy_n(ov.image.rgb.begin() + (static_cast<size_t>(r.y + y) * ov.image.width + r.x) * 3,
                  static_cast<size_t>(r.width) * 3, map.rgb.begin() + static_cast<size_t>(y) * r.width * 3);
    const std::string file = "img/overview-" + location + ".png";
    const std::vector<uint8_t> png = preview::encode_png(map);
    write_file_atomic(dir / file, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
    out[location] = {{"image", file},           {"x_west_m", ov.x_west_m}, {"y_north_m", ov.y_north_m},
                     {"m_per_px", ov.m_per_px}, {"width_px", r.width},     {"height_px", r.height}};
  }
  return out;
}

}  // namespace detail
}  // namespace nsg::report
