// The tiles of a report: five layer PNGs and one data file per tile, and the rows of the
// per-tile table. Shards are read one at a time; the tiles of a shard are rendered in
// parallel, each into its own files, so the output does not depend on the thread count.
#include <cmath>
#include <fstream>

#include "internal.h"
#include "nsg/io/tile_meta.h"
#include "nsg/core/build_info.h"
#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/core/version.h"
#include "nsg/graph/clip.h"
#include "nsg/graph/lane_attributes.h"
#include "nsg/metrics/edge_marks.h"
#include "nsg/metrics/io.h"
#include "nsg/preview/preview.h"

namespace nsg::report::detail {
namespace {

namespace fs = std::filesystem;

// Plain write: the whole report folder is renamed into place at the end.
void write_bytes(const fs::path& path, const void* data, size_t size) {
  std::ofstream f(path, std::ios::binary);
  f.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  f.close();
  NSG_CHECK(f.good(), IoError, path.string(), "", "a writable file (disk full?)");
}

// zlib level of the layer PNGs: most of the report's time is their compression; level 1
// is about 3× faster than 6 for files about a third larger.
constexpr int kPngLevel = 1;

const char* kMarkNames[] = {"correct", "wrong_direction", "unmatched", "zero_length"};

double round_to(double v, double step) { return std::round(v / step) * step; }

nlohmann::json graph_json(const metrics::CleanGraph& g) {
  nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
  for (const metrics::Point& p : g.nodes) nodes.push_back({round_to(p.u, 0.01), round_to(p.v, 0.01)});
  for (const auto& e : g.edges) edges.push_back({e[0], e[1]});
  return {{"nodes", std::move(nodes)}, {"edges", std::move(edges)}};
}

double lane_length_m(const metrics::Graph& g, double resolution_m) {
  double px = 0.0;
  for (const auto& e : g.edges) px += std::hypot(g.nodes[e[1]].u - g.nodes[e[0]].u, g.nodes[e[1]].v - g.nodes[e[0]].v);
  return px * resolution_m;
}

struct Meta {
  std::string location, split;
  std::vector<double> bounds_m;
  double resolution_m = 0.2;
  double coverage[3] = {0, 0, 0};
  int64_t vehicle_px = 0;
  nlohmann::json scenes = nlohmann::json::array();
};

// Through the checked reader (io/tile_meta.h): every field typed and in range.
Meta read_meta(const io::DatasetTile& tile) {
  const io::TileMeta t = tile.meta();
  Meta m;
  m.location = t.location;
  m.split = t.split;
  m.bounds_m.assign(t.bounds_m.begin(), t.bounds_m.end());
  m.resolution_m = t.resolution_m;
  m.coverage[0] = t.coverage_lidar;
  m.coverage[1] = t.coverage_rgb;
  m.coverage[2] = t.coverage_semantic;
  m.vehicle_px = t.vehicle_px;
  m.scenes = t.scenes;
  return m;
}

// The ground truth's lane changes and junction nodes for the tile view's overlays, by node
// index (the same nodes as its "gt" graph).
nlohmann::json attributes_json(const graph::TileGraph& g) {
  nlohmann::json changes = nlohmann::json::array(), junctions = nlohmann::json::array();
  for (const graph::TileLaneChange& c : g.lane_changes) changes.push_back({c.source, c.target});
  for (size_t n = 0; n < g.nodes.size(); ++n)
    if (g.nodes[n].junction != graph::Junction::kNone)
      junctions.push_back({n, graph::junction_name(g.nodes[n].junction)});
  return {{"lane_changes", std::move(changes)}, {"junctions", std::move(junctions)}};
}

// What a tile's layer images are made of: every member's bytes and the renderer (this
// build), so a rerun takes an earlier image only when both are unchanged.
std::string tile_fingerprint(const io::DatasetTile& tile) {
  Sha256 h;
  h.update(strprintf("nsgraph report layers\n%s\n%s\npng level %d\n", kVersion, git_commit(), kPngLevel));
  for (const auto& [suffix, bytes] : tile.files) {
    h.update(suffix + "\n" + std::to_string(bytes.size()) + "\n");
    h.update(bytes.data(), bytes.size());
  }
  return h.hex_digest();
}

fs::path layer_image(const fs::path& dir, const std::string& key, const char* layer) {
  return dir / "img" / (key + "." + layer + ".png");
}

// Links (else copies) the earlier report's images of `key` into `dir` when its fingerprint
// is unchanged and every image is there as a plain file; false (nothing written) otherwise.
bool reuse_images(const EarlierImages& earlier, const std::string& key, const std::string& fingerprint,
                  const fs::path& dir) {
  const auto it = earlier.fingerprints.find(key);
  if (earlier.dir.empty() || it == earlier.fingerprints.end() || it->second != fingerprint) return false;
  std::error_code ec;
  for (const char* layer : preview::kTileLayerNames)
    if (!fs::is_regular_file(fs::symlink_status(layer_image(earlier.dir, key, layer), ec))) return false;
  for (const char* layer : preview::kTileLayerNames) {
    const fs::path from = layer_image(earlier.dir, key, layer), to = layer_image(dir, key, layer);
    fs::create_hard_link(from, to, ec);  // the earlier folder is removed once the new one is in place
    if (ec) fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
    NSG_CHECK(!ec, IoError, to.string(), "", "a copy of " + from.string() + " (" + ec.message() + ")");
  }
  return true;
}

void render_images(const io::DatasetTile& tile, const fs::path& dir) {
  for (const char* layer : preview::kTileLayerNames) {
    const std::vector<uint8_t> png = preview::encode_png(preview::render_tile_layer(tile, layer), kPngLevel);
    write_bytes(layer_image(dir, tile.key, layer), png.data(), png.size());
  }
}

// What rendering one tile gave: its table row and how its images were made.
struct TileOutcome {
  TileRow row;
  std::string fingerprint;
  bool reused = false;
};

// The tile's data document before any prediction: what the tile is and where.
nlohmann::ordered_json tile_document(const io::DatasetTile& tile, const Meta& meta) {
  return {{"key", tile.key},
          {"location", meta.location},
          {"split", meta.split},
          {"bounds_m", meta.bounds_m},
          {"size_px", tile.raster("lidar.tif").width},
          {"resolution_m", meta.resolution_m},
          {"scenes", meta.scenes}};
}

// The table row's columns that the tile alone gives: coverage, vehicles, ground truth size.
TileRow ground_truth_row(const io::DatasetTile& tile, const Meta& meta, const metrics::Graph& gt) {
  TileRow row{tile.key, meta.location, meta.split, meta.bounds_m, {}};
  row.values["coverage_lidar"] = meta.coverage[0];
  row.values["coverage_rgb"] = meta.coverage[1];
  row.values["coverage_semantic"] = meta.coverage[2];
  row.values["vehicle_px"] = static_cast<double>(meta.vehicle_px);
  row.values["gt_nodes"] = static_cast<double>(gt.nodes.size());
  row.values["gt_edges"] = static_cast<double>(gt.edges.size());
  row.values["lane_length_m"] = round_to(lane_length_m(gt, meta.resolution_m), 0.01);
  return row;
}

// A prediction's edges marked against the ground truth: both graphs with their marks for
// the tile view and the mark counts.
struct MarkedGraphs {
  nlohmann::json gt, pred;  // pred: null without a prediction
  int64_t n_mark[4] = {0, 0, 0, 0};
  int64_t missed = 0;  // ground-truth edges no predicted edge matched
  int64_t pred_edges = 0;
};

MarkedGraphs marked_graphs(const metrics::Graph& gt, const metrics::Graph* pred, const metrics::MetricParams& params) {
  const metrics::EdgeMarks marks = metrics::mark_edges(gt, pred, params);
  MarkedGraphs out;
  nlohmann::json pred_marks = nlohmann::json::array(), gt_missed = nlohmann::json::array();
  for (metrics::PredEdgeMark m : marks.pred_marks) {
    ++out.n_mark[static_cast<int>(m)];
    pred_marks.push_back(static_cast<int>(m));
  }
  for (bool b : marks.gt_missed) {
    out.missed += b;
    gt_missed.push_back(b ? 1 : 0);
  }
  out.gt = graph_json(marks.gt);
  out.gt["missed"] = std::move(gt_missed);
  out.pred = nullptr;
  if (pred) {
    out.pred = graph_json(marks.pred);
    out.pred["marks"] = std::move(pred_marks);
  }
  out.pred_edges = static_cast<int64_t>(marks.pred.edges.size());
  return out;
}

nlohmann::ordered_json mark_counts(const MarkedGraphs& m) {
  nlohmann::ordered_json counts;
  for (int k = 0; k < 3; ++k) counts[kMarkNames[k]] = m.n_mark[k];
  counts["missed_gt"] = m.missed;
  return counts;
}

// The prediction's edges marked against the ground truth: both graphs with their marks for
// the tile view, the mark counts, and the row's prediction columns.
void add_edge_marks(const io::DatasetTile& tile, const TileInputs& in, const metrics::Graph& gt,
                    nlohmann::ordered_json& doc, TileRow& row) {
  const auto p = in.prediction->find(tile.key);
  const metrics::Graph* pred = p == in.prediction->end() ? nullptr : &p->second;
  MarkedGraphs m = marked_graphs(gt, pred, in.scores->params);
  doc["gt"] = std::move(m.gt);
  doc["pred"] = std::move(m.pred);
  doc["marks"] = mark_counts(m);
  row.values["missing_prediction"] = pred ? 0.0 : 1.0;
  row.values["pred_edges"] = static_cast<double>(m.pred_edges);
  row.values["wrong_direction_edges"] = static_cast<double>(m.n_mark[1]);
  row.values["unmatched_edges"] = static_cast<double>(m.n_mark[2]);
  row.values["missed_gt_edges"] = static_cast<double>(m.missed);
}

// The submission's metrics and counts of the tile.
void add_scores(const metrics::TileMeasurement& s, nlohmann::ordered_json& doc, TileRow& row) {
  nlohmann::ordered_json values, tile_counts;
  for (int m = 0; m < metrics::kMetricCount; ++m) {
    values[metrics::metric_name(m)] = rounded(s.values[m]);
    row.values[metrics::metric_name(m)] = s.values[m];
  }
  for (int c = 0; c < metrics::kCountCount; ++c) tile_counts[metrics::count_name(c)] = s.counts[c];
  doc["metrics"] = std::move(values);
  doc["counts"] = std::move(tile_counts);
}

// The baseline's metrics, their differences to the submission's, and its graph.
void add_baseline(const io::DatasetTile& tile, const TileInputs& in, const metrics::TileMeasurement& s,
                  const metrics::TileMeasurement& b, nlohmann::ordered_json& doc, TileRow& row) {
  nlohmann::ordered_json base;
  for (int m = 0; m < metrics::kMetricCount; ++m) {
    const std::optional<double>& mine = s.values[m];
    const std::optional<double>& theirs = b.values[m];
    base[metrics::metric_name(m)] = rounded(theirs);
    row.values[std::string("baseline.") + metrics::metric_name(m)] = theirs;
    // Per tile, submission − baseline: sorting by it finds where the two differ most.
    row.values[std::string("delta.") + metrics::metric_name(m)] =
        mine && theirs ? std::optional<double>(*mine - *theirs) : std::nullopt;
  }
  doc["baseline"] = std::move(base);
  // The baseline's graph for the tile view's overlay (null: no prediction for the tile).
  nlohmann::json base_graph = nullptr;
  if (in.baseline_prediction) {
    const auto bp = in.baseline_prediction->find(tile.key);
    if (bp != in.baseline_prediction->end()) base_graph = graph_json(metrics::clean_graph(bp->second));
  }
  doc["base"] = std::move(base_graph);
}

// One tile: its images, its data file, its table row.
TileOutcome render_tile(const io::DatasetTile& tile, const TileInputs& in,
                        const std::map<std::string, const metrics::TileMeasurement*>& scores,
                        const std::map<std::string, const metrics::TileMeasurement*>& baseline,
                        const nlohmann::ordered_json* rungs, const EarlierImages& earlier, const fs::path& dir) {
  const Meta meta = read_meta(tile);
  TileOutcome outcome;
  outcome.fingerprint = tile_fingerprint(tile);
  outcome.reused = reuse_images(earlier, tile.key, outcome.fingerprint, dir);
  if (!outcome.reused) render_images(tile, dir);
  const graph::TileGraph tile_graph = tile.graph();
  const metrics::Graph gt = metrics::graph_of_tile(tile_graph);
  TileRow row = ground_truth_row(tile, meta, gt);
  nlohmann::ordered_json doc = tile_document(tile, meta);
  doc["attributes"] = attributes_json(tile_graph);
  if (rungs) doc["rungs"] = *rungs;
  if (in.prediction) {
    add_edge_marks(tile, in, gt, doc, row);
    const auto s = scores.find(tile.key);
    NSG_CHECK(s != scores.end(), InternalError, "", tile.key, "a score for every tile of the split");
    add_scores(*s->second, doc, row);
    if (in.baseline) {
      const auto b = baseline.find(tile.key);
      NSG_CHECK(b != baseline.end(), InternalError, "", tile.key, "a baseline score for every tile of the split");
      add_baseline(tile, in, *s->second, *b->second, doc, row);
    }
  } else {
    doc["gt"] = graph_json(metrics::clean_graph(gt));
  }
  nlohmann::ordered_json figures;
  for (const auto& [k, v] : row.values) figures[k] = rounded(v);
  doc["figures"] = std::move(figures);
  const std::string script = data_script("tile:" + tile.key, doc.dump());
  write_bytes(dir / "data" / "tile" / (tile.key + ".js"), script.data(), script.size());
  outcome.row = std::move(row);
  return outcome;
}

// --- The observation ladder (generate --ladder): the split tiles' rung tiles, drawn beside
// them in the tile view.

// Rung k's per-tile scores by the split tile's key (the rung reports score under it).
using RungScores = std::map<std::pair<int, std::string>, const metrics::TileMeasurement*>;

RungScores rung_scores_by_key(const TileInputs& in) {
  RungScores out;
  if (in.rung_scores)
    for (const auto& [rung, report] : *in.rung_scores)
      for (const metrics::TileMeasurement& t : report.tiles) out[{rung, t.key}] = &t;
  return out;
}

// A rung tile's entry in its split tile's data file: the rung, the scenes it was built from
// and their layers' coverage; with a submission, its prediction for the rung key marked
// against the tile's ground truth (the same graph at every rung) and its metrics.
nlohmann::ordered_json rung_entry(const io::DatasetTile& tile, const io::TileMeta& meta, const TileInputs& in,
                                  const RungScores& scores) {
  const io::TileRung& r = *meta.ladder;
  nlohmann::ordered_json e = {{"rung", r.rung},
                              {"key", tile.key},
                              {"scenes", meta.scenes},
                              {"capture_dates", r.capture_dates},
                              {"scenes_seen", r.scenes_seen},
                              {"coverage_lidar", rounded(meta.coverage_lidar)},
                              {"coverage_rgb", rounded(meta.coverage_rgb)},
                              {"coverage_semantic", rounded(meta.coverage_semantic)},
                              {"vehicle_px", meta.vehicle_px}};
  if (!in.prediction) return e;
  const auto p = in.prediction->find(tile.key);
  const metrics::Graph* pred = p == in.prediction->end() ? nullptr : &p->second;
  MarkedGraphs m = marked_graphs(metrics::graph_of_tile(tile.graph()), pred, in.scores->params);
  e["missed"] = std::move(m.gt["missed"]);
  e["pred"] = std::move(m.pred);
  e["marks"] = mark_counts(m);
  const auto s = scores.find({r.rung, r.base_key});
  if (s != scores.end()) {
    nlohmann::ordered_json values;
    for (int k = 0; k < metrics::kMetricCount; ++k) values[metrics::metric_name(k)] = rounded(s->second->values[k]);
    e["metrics"] = std::move(values);
  }
  return e;
}

// One rung tile: its images (img/<key>-r<k>.<layer>.png) and its entry.
struct RungOutcome {
  std::string base_key;
  int rung = 0;
  nlohmann::ordered_json entry;
  std::string fingerprint;
  bool reused = false;
};

RungOutcome render_rung_tile(const io::DatasetTile& tile, const TileInputs& in, const RungScores& scores,
                             const EarlierImages& earlier, const fs::path& dir) {
  const io::TileMeta meta = tile.meta();
  NSG_CHECK(meta.ladder.has_value(), DataError, tile.shard, tile.key, "a rung tile's meta.json with its ladder");
  RungOutcome out{meta.ladder->base_key, meta.ladder->rung, rung_entry(tile, meta, in, scores), tile_fingerprint(tile)};
  out.reused = reuse_images(earlier, tile.key, out.fingerprint, dir);
  if (!out.reused) render_images(tile, dir);
  return out;
}

// The rung tiles of `split`'s tiles: their images, fingerprints and image counts into `pass`,
// their entries by split tile key (each an array by rung). None for a split that is itself a
// rung ("test-r1").
std::map<std::string, nlohmann::ordered_json> write_rung_tiles(const io::Dataset& dataset, const std::string& split,
                                                               const TileInputs& inputs, const EarlierImages& earlier,
                                                               const fs::path& dir, int threads, bool progress,
                                                               nlohmann::json& fingerprints, TilePass& pass) {
  std::map<std::string, std::map<int, nlohmann::ordered_json>> by_base;
  const std::vector<io::ShardEntry> shards =
      io::rung_split(split) ? std::vector<io::ShardEntry>{} : dataset.rung_shards(split);
  if (shards.empty()) return {};
  const RungScores scores = rung_scores_by_key(inputs);
  Progress bar("report rung tiles", io::tile_count(shards), progress);
  const int64_t layers = static_cast<int64_t>(std::size(preview::kTileLayerNames));
  for (const io::ShardEntry& shard : shards) {
    const std::vector<io::DatasetTile> tiles = dataset.read_shard(shard);
    std::vector<RungOutcome> done(tiles.size());
    parallel_for(tiles.size(), threads, [&](size_t i) {
      done[i] = render_rung_tile(tiles[i], inputs, scores, earlier, dir);
      bar.advance();
    });
    for (size_t i = 0; i < tiles.size(); ++i) {
      fingerprints[tiles[i].key] = done[i].fingerprint;
      pass.images_reused += done[i].reused ? layers : 0;
      by_base[done[i].base_key][done[i].rung] = std::move(done[i].entry);
    }
    pass.images += static_cast<int64_t>(tiles.size()) * layers;
  }
  bar.finish();
  std::map<std::string, nlohmann::ordered_json> out;
  for (auto& [key, rungs] : by_base) {
    nlohmann::ordered_json& list = out[key] = nlohmann::ordered_json::array();
    for (auto& [rung, entry] : rungs) list.push_back(std::move(entry));
  }
  return out;
}

std::map<std::string, const metrics::TileMeasurement*> by_key(const metrics::ScoreReport* r) {
  std::map<std::string, const metrics::TileMeasurement*> out;
  if (r)
    for (const auto& t : r->tiles) out[t.key] = &t;
  return out;
}

}  // namespace

namespace {
// The per-tile columns a scored submission adds beside the metrics (tile_document sets
// them), and which way is better: declared once for the columns and the sort arrows.
struct PredictionColumn {
  const char* name;
  bool lower_is_better;
};
constexpr PredictionColumn kPredictionColumns[] = {{"missing_prediction", true},
                                                   {"pred_edges", false},
                                                   {"wrong_direction_edges", true},
                                                   {"unmatched_edges", true},
                                                   {"missed_gt_edges", true}};
}  // namespace

std::vector<std::string> lower_is_better_columns() {
  std::vector<std::string> out;
  for (int m = 0; m < metrics::kMetricCount; ++m)
    if (metrics::metric_info(m).lower_is_better) out.push_back(metrics::metric_name(m));
  for (const PredictionColumn& c : kPredictionColumns)
    if (c.lower_is_better) out.push_back(c.name);
  return out;
}

std::vector<std::string> table_columns(bool submission, bool baseline) {
  std::vector<std::string> cols;
  if (submission) {
    // With a baseline, each metric's difference and baseline value sit beside it: the table
    // is read metric by metric, and 3 × the metrics would push a block of Δ off-screen.
    for (int m = 0; m < metrics::kMetricCount; ++m) {
      cols.push_back(metrics::metric_name(m));
      if (!baseline) continue;
      cols.push_back(std::string("delta.") + metrics::metric_name(m));
      cols.push_back(std::string("baseline.") + metrics::metric_name(m));
    }
    for (const PredictionColumn& c : kPredictionColumns) cols.push_back(c.name);
  }
  for (const char* c :
       {"gt_nodes", "gt_edges", "lane_length_m", "coverage_lidar", "coverage_rgb", "coverage_semantic", "vehicle_px"})
    cols.push_back(c);
  return cols;
}

EarlierImages earlier_images(const fs::path& report) {
  // Our own output, but a folder anyone could have edited: anything odd means no reuse.
  constexpr uintmax_t kMaxBytes = 64ull << 20;
  EarlierImages e;
  std::error_code ec;
  const fs::path file = report / kFingerprints;
  if (!fs::is_regular_file(fs::symlink_status(file, ec)) || fs::file_size(file, ec) > kMaxBytes || ec) return e;
  try {
    const nlohmann::json doc = nlohmann::json::parse(read_file(file));
    for (const auto& [key, fp] : doc.at("tiles").items())
      if (fp.is_string()) e.fingerprints[key] = fp.get<std::string>();
  } catch (const std::exception&) {
    e.fingerprints.clear();
  }
  // Images are taken only from the report's own img/ folder, never through a link out of it.
  if (!e.fingerprints.empty() && fs::is_directory(fs::symlink_status(report / "img", ec))) e.dir = report;
  return e;
}

TilePass write_tile_pages(const io::Dataset& dataset, const std::string& split, const TileInputs& inputs,
                          const EarlierImages& earlier, const fs::path& dir, int threads, bool progress) {
  fs::create_directories(dir / "img");
  fs::create_directories(dir / "data" / "tile");
  const auto scores = by_key(inputs.scores);
  const auto baseline = by_key(inputs.baseline);
  TilePass pass;
  nlohmann::json fingerprints = nlohmann::json::object();
  const std::map<std::string, nlohmann::ordered_json> rungs =
      write_rung_tiles(dataset, split, inputs, earlier, dir, threads, progress, fingerprints, pass);
  Progress bar("report tiles", dataset.tile_count(split), progress);
  for (const io::ShardEntry& shard : dataset.shards(split)) {
    const std::vector<io::DatasetTile> tiles = dataset.read_shard(shard);
    std::vector<TileOutcome> done(tiles.size());
    parallel_for(tiles.size(), threads, [&](size_t i) {
      const auto r = rungs.find(tiles[i].key);
      done[i] = render_tile(tiles[i], inputs, scores, baseline, r == rungs.end() ? nullptr : &r->second, earlier, dir);
      bar.advance();
    });
    const int64_t layers = static_cast<int64_t>(std::size(preview::kTileLayerNames));
    for (TileOutcome& t : done) {
      fingerprints[t.row.key] = t.fingerprint;
      pass.images_reused += t.reused ? layers : 0;
      pass.rows.push_back(std::move(t.row));
    }
    pass.images += static_cast<int64_t>(tiles.size()) * layers;
    if (!earlier.dir.empty())
      bar.set_detail(strprintf("%lld images reused", static_cast<long long>(pass.images_reused)));
  }
  bar.finish();
  const std::string text = nlohmann::json{{"tiles", std::move(fingerprints)}}.dump() + "\n";
  write_bytes(dir / kFingerprints, text.data(), text.size());
  return pass;
}

}  // namespace nsg::report::detail
