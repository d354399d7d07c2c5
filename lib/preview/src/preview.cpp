// write_previews: which tiles go into which image, submission scoring and sorting, files.
#include <algorithm>
#include <set>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/log.h"
#include "nsg/core/progress.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/io.h"
#include "nsg/validate/submission.h"
#include "nsg/preview/preview.h"
#include "draw.h"

namespace nsg::preview {

namespace fs = std::filesystem;

namespace {

// Metric index of a metric name; -1 if none.
int metric_index(const std::string& name) {
  for (int m = 0; m < metrics::kMetricCount; ++m)
    if (name == metrics::metric_name(m)) return m;
  return -1;
}

bool lower_is_better(int metric) { return metrics::metric_info(metric).lower_is_better; }

std::vector<io::ShardEntry> selected_shards(const io::Dataset& ds, const PreviewOptions& o) {
  std::vector<io::ShardEntry> out;
  for (const io::ShardEntry& s : ds.shards(o.split)) {
    if (o.shard && !ends_with(s.name, strprintf("-%06d", *o.shard))) continue;
    out.push_back(s);
  }
  NSG_CHECK(!out.empty() || !o.shard, ConfigError, (ds.root() / "manifest.json").string(), "--shard",
            strprintf("a shard numbered %d%s", *o.shard, o.split.empty() ? "" : (" in split " + o.split).c_str()));
  return out;
}

void write_png(const fs::path& file, const Image& image, std::vector<fs::path>& written) {
  const std::vector<uint8_t> png = encode_png(image);
  write_file_atomic(file, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
  log::info(strprintf("wrote %s (%d x %d px)", file.string().c_str(), image.width, image.height));
  written.push_back(file);
}

metrics::Graph gt_graph(const io::DatasetTile& t) { return metrics::tile_graph(t); }

metrics::MetricParams params_of(const io::DatasetTile& t) {
  const io::TileMeta meta = t.meta();
  metrics::MetricParams p;
  p.resolution_m = meta.resolution_m;
  p.size_px = meta.size_px;
  p.validate();
  return p;
}

void write_shard_mosaics(const io::Dataset& ds, const fs::path& out, const PreviewOptions& o,
                         std::vector<fs::path>& written) {
  const auto shards = selected_shards(ds, o);
  Progress bar("preview shards", shards.size(), o.progress);
  for (const auto& shard : shards) {
    bar.advance();
    std::vector<io::DatasetTile> tiles = ds.read_shard(shard);
    if (tiles.empty()) continue;
    if (static_cast<int>(tiles.size()) > o.max_tiles) tiles.resize(o.max_tiles);
    std::vector<CardInput> cards;
    for (const auto& t : tiles) cards.push_back({&t, false, nullptr, nullptr});
    const std::string& name = shard.name;  // <split>-NNNNNN: the manifest's reader checked it
    write_png(OutputFolder(out).prepare(name + ".png"), render_mosaic(name, cards, o.mosaic).image, written);
  }
}

// The split a submission's keys are tiles of, when --split is not given: without it the
// train tiles (no prediction) were scored too and shown as the worst.
std::string split_of_submission(const io::Dataset& ds, const metrics::GraphSet& pred, const std::string& file) {
  std::vector<std::string> keys;
  for (const auto& kv : pred) keys.push_back(kv.first);
  std::string why;
  const std::optional<std::string> split = ds.split_of_keys(keys, why);
  NSG_CHECK(split, DataError, file, "tiles", "keys of one split of the dataset: " + why);
  log::info("split '" + *split + "' (the split the submission's keys are tiles of)");
  return *split;
}

void write_submission_mosaic(const io::Dataset& ds, const fs::path& out, const PreviewOptions& given,
                             std::vector<fs::path>& written) {
  const nlohmann::json doc = metrics::read_json_file(given.submission);
  // Out-of-range indices or non-finite numbers would otherwise reach the scorer.
  const Issues issues = validate::check_submission_structure(doc, given.submission);
  NSG_CHECK(issues.empty(), DataError, given.submission, "structure",
            "a valid submission (run `nsgraph validate`):\n" + issues.format());
  const metrics::GraphSet pred = metrics::graphs_from_submission(doc, given.submission);
  PreviewOptions o = given;
  if (o.split.empty()) o.split = split_of_submission(ds, pred, o.submission);
  const auto shards = selected_shards(ds, o);
  // Pass 1: scores of every tile (graphs only), to choose the tiles shown.
  std::vector<metrics::TileMeasurement> scored;
  Progress bar("preview scoring tiles", io::tile_count(shards), o.progress);
  for (const auto& shard : shards)
    for (const auto& t : ds.read_shard(shard)) {
      const auto p = pred.find(t.key);
      scored.push_back(metrics::measure(t.key, gt_graph(t), p == pred.end() ? nullptr : &p->second, params_of(t)));
      bar.advance();
    }
  bar.finish();
  NSG_CHECK(!scored.empty(), DataError, (ds.root() / "manifest.json").string(), o.split, "tiles to compare");
  if (!o.sort.empty()) scored = worst_first(std::move(scored), o.sort);
  log::info(strprintf("%zu tile(s) scored; showing %s", scored.size(),
                      o.sort.empty() ? "the first in key order" : ("the worst by " + o.sort).c_str()));
  if (static_cast<int>(scored.size()) > o.max_tiles) scored.resize(o.max_tiles);
  // Pass 2: the chosen tiles' layers, one shard in memory at a time.
  std::map<std::string, size_t> rank;
  for (size_t i = 0; i < scored.size(); ++i) rank[scored[i].key] = i;
  std::vector<io::DatasetTile> tiles(scored.size());
  for (const auto& shard : shards)
    for (auto& t : ds.read_shard(shard))
      if (const auto r = rank.find(t.key); r != rank.end()) tiles[r->second] = std::move(t);
  std::vector<CardInput> cards;
  for (size_t i = 0; i < tiles.size(); ++i) {
    const auto p = pred.find(tiles[i].key);
    cards.push_back({&tiles[i], true, p == pred.end() ? nullptr : &p->second, &scored[i]});
  }
  const std::string name = "submission-" + (o.split.empty() ? std::string("all") : o.split);
  write_png(OutputFolder(out).prepare(name + ".png"), render_mosaic(name, cards, o.mosaic).image, written);
}

}  // namespace

std::vector<metrics::TileMeasurement> worst_first(std::vector<metrics::TileMeasurement> tiles,
                                                  const std::string& metric) {
  const int m = metric_index(metric);
  NSG_CHECK(m >= 0, ConfigError, "", "--sort", "a metric name of the score report, got '" + metric + "'");
  const bool lower = lower_is_better(m);
  std::sort(tiles.begin(), tiles.end(), [&](const metrics::TileMeasurement& a, const metrics::TileMeasurement& b) {
    const auto& va = a.values[m];
    const auto& vb = b.values[m];
    if (va.has_value() != vb.has_value()) return va.has_value();  // undefined last
    if (va && *va != *vb) return lower ? *va > *vb : *va < *vb;
    return a.key < b.key;
  });
  return tiles;
}

void PreviewOptions::validate() const {
  NSG_CHECK(max_tiles >= 1 && max_tiles <= 1024, ConfigError, "", "--max-tiles", "1 … 1024");
  NSG_CHECK(!shard || *shard >= 0, ConfigError, "", "--shard", "a shard number ≥ 0");
  NSG_CHECK(sort.empty() || metric_index(sort) >= 0, ConfigError, "", "--sort",
            "a metric name of the score report (e.g. apls, f1, topo_f1), got '" + sort + "'");
  NSG_CHECK(sort.empty() || !submission.empty(), ConfigError, "", "--sort", "--submission (scores to sort by)");
  NSG_CHECK(!(overview && !submission.empty()), ConfigError, "", "--overview", "either --overview or --submission");
  mosaic.validate();
  overview_options.validate();
}

std::vector<fs::path> write_previews(const fs::path& dataset, const fs::path& out_dir, const PreviewOptions& options) {
  options.validate();
  const io::Dataset ds = io::Dataset::open(dataset);
  ds.require_split(options.split);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  NSG_CHECK(!ec, IoError, out_dir.string(), "directory", "a creatable output folder: " + ec.message());
  std::vector<fs::path> written;
  if (options.overview) {
    for (const io::ManifestLocation& loc : ds.manifest().locations) {
      const std::string& name = loc.name;  // [A-Za-z0-9_-]: the manifest's reader checked it
      write_png(OutputFolder(out_dir).prepare("overview-" + name + ".png"),
                render_overview(ds, name, options.split, options.overview_options).image, written);
    }
  } else if (!options.submission.empty()) {
    write_submission_mosaic(ds, out_dir, options, written);
  } else {
    write_shard_mosaics(ds, out_dir, options, written);
  }
  return written;
}

}  // namespace nsg::preview
