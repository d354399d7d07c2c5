#include "nsg/validate/dataset.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <regex>
#include <set>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/core/progress.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/graph/lane_attributes.h"
#include "nsg/io/dataset.h"
#include "nsg/io/raster.h"
#include "nsg/io/tile_graph.h"
#include "nsg/io/tile_members.h"
#include "nsg/io/tile_meta.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/schema.h"
#include "ladder_checks.h"
#include "raster_values.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::validate {

const std::vector<CheckInfo>& dataset_checks() {
  static const std::vector<CheckInfo> kChecks = {
      {"manifest.schema", "manifest.json validates against schemas/v1/manifest.schema.json"},
      {"determinism.config",
       "the manifest's config validates against generate-config.schema.json; its seed, "
       "size_px, resolution_m and layout equal the manifest's"},
      {"maps.sha256", "every manifest maps/ file exists with the recorded sha256 and size"},
      {"shard.present", "every manifest shard file exists"},
      {"shard.sha256", "every shard file hashes to the manifest's sha256 and has its byte size (tar layout)"},
      {"shard.readable", "every shard is a complete tar of <key>.<suffix> members"},
      {"shard.members", "every key has exactly the files of tile_format.files"},
      {"tile.key",
       "keys are <location>-<split>-<NNNNNN>, unique, of the shard's split and range, and equal "
       "the key inside graph.json and meta.json"},
      {"meta.schema",
       "meta.json validates against tile-meta.schema.json and agrees with the shard and "
       "tile_format (split, location, size_px, resolution_m, bounds extent)"},
      {"meta.counts", "meta counts (nodes, edges, vehicle_px) and coverage fractions match the files"},
      {"raster.readable", "every .tif decodes as a georeferenced GeoTIFF"},
      {"raster.size", "every raster is tile_format.size_px square"},
      {"raster.dtype", "lidar/semantic/coverage uint8 x1, rgb uint8 x3, vehicle float32 x1"},
      {"raster.nodata", "vehicle in {-1} or [0, 1); coverage flags in 0..7 and set wherever a layer has data"},
      {"raster.georef", "GeoTIFF location, north-west corner and pixel size match meta (location, bounds_m)"},
      {"graph.schema", "graph.json validates against tile-graph.schema.json"},
      {"graph.indices", "node ids equal their position; edge source/target are node ids"},
      {"graph.pixel_coords", "u = (x - x_west)/res - 0.5 and v = (y_north - y)/res - 0.5 for every node"},
      {"graph.in_tile", "every node lies inside the tile's bounds"},
      {"graph.edge_length", "every edge is at most config graph.max_spacing_m long (border-cut edges are shorter)"},
      {"graph.self_loops", "no edge joins a node to itself"},
      {"graph.duplicates", "no directed edge appears twice"},
      {"graph.lane_changes",
       "lane changes join two different nodes at most a lane change's reach apart (docs/dataset-format.md)"},
      {"split.disjoint",
       "no tile of one split overlaps a region or a tile of another split (not checked for splits.preset "
       "before-after, whose splits share streets by design)"},
      {"split.counts", "manifest counts (per shard, split, location, total) equal the tiles found"},
      {"ladder.rungs",
       "a ladder's rung tiles (generate --ladder) are keyed <base_key>-r<rung> in shards of their rung, have their "
       "split tile's crop, region and graph, at most <rung> of its scenes, and the manifest's rung counts"},
  };
  return kChecks;
}

bool check_selected(const std::string& patterns, const std::string& check) {
  if (patterns.empty()) return true;
  for (const std::string& p : split(patterns, ','))
    if (wildcard_match(std::string(trim(p)), check)) return true;
  return false;
}

void DatasetValidateOptions::validate() const {
  NSG_CHECK(!root.empty(), ConfigError, "", "DATASET", "a dataset folder");
  const auto& all = dataset_checks();
  NSG_CHECK(std::any_of(all.begin(), all.end(), [&](const CheckInfo& c) { return check_selected(checks, c.name); }),
            ConfigError, "", "--checks",
            "a pattern matching at least one check (see --list-checks), got '" + checks + "'");
  NSG_CHECK(length_tolerance_m >= 0 && std::isfinite(length_tolerance_m), ConfigError, "", "length_tolerance_m",
            "a finite tolerance >= 0");
}

namespace {

struct Rect {
  double x_west = 0, y_south = 0, x_east = 0, y_north = 0;
};

// Area-positive overlap (touching edges do not count).
bool overlaps(const Rect& a, const Rect& b, double tol) {
  return std::min(a.x_east, b.x_east) - std::max(a.x_west, b.x_west) > tol &&
         std::min(a.y_north, b.y_north) - std::max(a.y_south, b.y_south) > tol;
}

double num_or(const json& j, const json::json_pointer& ptr, double fallback) {
  return j.contains(ptr) && j.at(ptr).is_number() ? j.at(ptr).get<double>() : fallback;
}

std::string str_of(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
}

struct TileRecord {
  std::string key, split, location, shard;
  Rect bounds;
};

Rect rect_of(const io::TileMeta& meta) {
  return Rect{meta.bounds_m[0], meta.bounds_m[1], meta.bounds_m[2], meta.bounds_m[3]};
}

// Metres between two nodes of `g` (indices the reader checked).
double distance_m(const graph::TileGraph& g, int32_t a, int32_t b) {
  const graph::TileNode& p = g.nodes[static_cast<size_t>(a)];
  const graph::TileNode& q = g.nodes[static_cast<size_t>(b)];
  return std::hypot(q.x_m - p.x_m, q.y_m - p.y_m);
}

struct RasterSpec {
  std::string suffix;
  io::SampleType type;
  int bands;
};
// The raster members as io declares them (io/tile_members.h).
const std::vector<RasterSpec>& raster_specs() {
  static const std::vector<RasterSpec> specs = [] {
    std::vector<RasterSpec> out;
    for (const io::TileMember* m : io::raster_members()) out.push_back({m->file, m->dtype, m->bands});
    return out;
  }();
  return specs;
}

class DatasetChecker {
 public:
  // `document`: the manifest as parsed, for the schema check and the config's comparisons;
  // everything else reads the typed manifest.
  DatasetChecker(const DatasetValidateOptions& o, const io::Dataset& ds, json document, const fs::path& schemas)
      : o_(o), ds_(ds), m_(ds.manifest()), document_(std::move(document)), schemas_(schemas) {
    size_px_ = m_.tile_format.size_px;
    res_m_ = m_.tile_format.resolution_m;
    max_spacing_m_ = num_or(document_, json::json_pointer("/config/graph/max_spacing_m"), 2.0);
    files_.insert(m_.tile_format.files.begin(), m_.tile_format.files.end());
    if (files_.empty())
      for (const io::TileMember& m : io::tile_members()) files_.insert(m.file);
    if (on("meta.schema")) meta_schema_.emplace(schema_path("tile-meta", schemas));
    if (on("graph.schema")) graph_schema_.emplace(schema_path("tile-graph", schemas));
  }

  Issues run() {
    check_manifest();
    check_maps();
    const std::vector<io::ShardEntry>& shards = m_.shards;
    const std::vector<io::ShardEntry> rung_shards = ds_.rung_shards();
    // Hashing and decoding every tile takes a while on a real dataset.
    Progress bar("validate shards", shards.size() + rung_shards.size(), o_.progress);
    for (const io::ShardEntry& shard : shards) {
      check_shard(shard);
      bar.advance();
    }
    for (const io::ShardEntry& shard : rung_shards) {
      check_shard(shard);
      bar.advance();
    }
    bar.finish();
    check_split_disjoint();
    check_split_counts();
    if (on("ladder.rungs") && m_.ladder)
      check_ladder_tiles(
          *m_.ladder, ladder_, found_per_shard_,
          [this](const std::string& c, const std::string& s, const std::string& msg) { error(c, s, msg); });
    return std::move(issues_);
  }

 private:
  bool on(const std::string& check) const { return check_selected(o_.checks, check); }
  void error(const std::string& check, const std::string& subject, const std::string& message) {
    if (on(check)) issues_.error(check, subject, message);
  }
  bool near(double a, double b) const { return std::abs(a - b) <= o_.length_tolerance_m; }

  void check_manifest() {
    if (on("manifest.schema"))
      issues_.append(
          SchemaValidator(schema_path("manifest", schemas_)).validate(document_, "manifest.json", "manifest.schema"));
    if (!on("determinism.config")) return;
    const json config = json(m_.config);  // an object: the manifest's reader checked it
    issues_.append(SchemaValidator(schema_path("generate-config", schemas_))
                       .validate(config, "manifest.json:/config", "determinism.config"));
    // The config as written against the typed manifest's value (its reader checked it).
    const auto differs = [&](const char* config_ptr, const char* manifest_ptr, const json& manifest_value) {
      const json::json_pointer a(config_ptr);
      if (config.contains(a) && config.at(a) == manifest_value) return;
      error("determinism.config", std::string("manifest.json:") + manifest_ptr,
            std::string("equal to config ") + config_ptr + " (" +
                (config.contains(a) ? config.at(a).dump() : "absent") + " vs " + manifest_value.dump() + ")");
    };
    differs("/seed", "/seed", m_.seed);
    differs("/crops/size_px", "/tile_format/size_px", m_.tile_format.size_px);
    differs("/resolution_m", "/tile_format/resolution_m", m_.tile_format.resolution_m);
    differs("/output/layout", "/layout", m_.tar_layout() ? "tar" : "folder");
  }

  void check_file_hash(const std::string& check, const fs::path& path, const std::string& want_sha256,
                       int64_t want_bytes, const std::string& subject) {
    const std::string got = sha256_file(path);
    if (got != want_sha256) error(check, subject, "sha256 " + got + ", manifest says " + want_sha256);
    const auto bytes = static_cast<int64_t>(fs::file_size(path));
    if (bytes != want_bytes)
      error(check, subject, std::to_string(bytes) + " bytes, manifest says " + std::to_string(want_bytes));
  }

  void check_maps() {
    if (!on("maps.sha256")) return;
    for (const io::FileRecord& f : m_.maps) {
      const fs::path path = ds_.root() / f.file;  // inside the dataset: the manifest's reader checked it
      if (!fs::is_regular_file(path)) {
        error("maps.sha256", f.file, "missing file listed in manifest maps");
        continue;
      }
      check_file_hash("maps.sha256", path, f.sha256, f.bytes, f.file);
    }
  }

  void check_shard(const io::ShardEntry& shard) {
    const std::string& name = shard.name;
    found_per_shard_[name] += 0;
    // The path stays inside the dataset (the manifest's reader checked it).
    const fs::path path = ds_.root() / shard.path();
    if (ds_.tar_layout()) {
      if (!fs::is_regular_file(path)) {
        error("shard.present", name, "shard file '" + shard.file + "' is missing");
        if (!on("shard.present")) error("shard.readable", name, "shard file is missing");
        return;
      }
      if (on("shard.sha256")) check_file_hash("shard.sha256", path, shard.sha256, shard.bytes, name);
    } else if (!fs::is_directory(path)) {
      error("shard.present", name, "folder '" + shard.folder + "' is missing");
      return;
    }
    std::vector<io::DatasetTile> tiles;
    try {
      tiles = ds_.read_shard(shard);
    } catch (const Error& e) {
      error("shard.readable", name, e.what());
      return;
    }
    found_per_shard_[name] = static_cast<int64_t>(tiles.size());
    for (const io::DatasetTile& t : tiles) check_tile(t, shard);
  }

  void check_key(const io::DatasetTile& t, const io::ShardEntry& shard) {
    static const std::regex kKey(R"(([^.]+)-(train|val|test)-(\d{6})(-r([1-9]\d*))?)");
    std::smatch m;
    const std::string subject = t.shard + "/" + t.key;
    const std::string rung = shard.rung > 0 ? std::to_string(shard.rung) : "";
    if (!std::regex_match(t.key, m, kKey) || m[5].str() != rung) {
      error("tile.key", subject,
            rung.empty() ? "a key <location>-<split>-<NNNNNN>" : "a key <location>-<split>-<NNNNNN>-r" + rung);
    } else {
      if (m[2] != shard.split) error("tile.key", subject, "a key of split '" + shard.split + "'");
      if (m[1] != shard.location) error("tile.key", subject, "a key of location '" + shard.location + "'");
    }
    if (t.key < shard.first_key || t.key > shard.last_key)
      error("tile.key", subject, "a key in the shard's range [" + shard.first_key + ", " + shard.last_key + "]");
    if (!keys_.insert(t.key).second) error("tile.key", subject, "a unique key (seen in an earlier tile)");
  }

  void check_members(const io::DatasetTile& t) {
    const std::string subject = t.shard + "/" + t.key;
    for (const std::string& f : files_)
      if (!t.has(f)) error("shard.members", subject + "." + f, "missing member");
    for (const auto& [suffix, bytes] : t.files)
      if (!files_.count(suffix))
        error("shard.members", subject + "." + suffix, "unexpected member (not in tile_format.files)");
  }

  // Parses a JSON member; a parse failure is reported under `check`.
  std::optional<json> parse_member(const io::DatasetTile& t, const std::string& suffix, const std::string& check) {
    if (!t.has(suffix)) return std::nullopt;
    try {
      return t.json(suffix);
    } catch (const Error& e) {
      error(check, t.shard + "/" + t.key + "." + suffix, e.what());
      return std::nullopt;
    }
  }

  // Schema checks on the documents as written, then the typed models' checks: the meta
  // and the graph are read by their one reader (io/tile_meta.h, io/tile_graph.h), and
  // every check below runs over what the reader gives.
  void check_tile(const io::DatasetTile& t, const io::ShardEntry& shard) {
    check_key(t, shard);
    check_members(t);
    const std::optional<json> meta_doc = parse_member(t, "meta.json", "meta.schema");
    std::optional<io::TileMeta> meta;
    if (meta_doc) meta = read_meta(t, *meta_doc);
    if (meta) check_meta(t, *meta, shard);
    const std::optional<json> graph_doc = parse_member(t, "graph.json", "graph.schema");
    if (graph_doc)
      if (const std::optional<ReadGraph> graph = read_graph(t, *graph_doc)) check_graph(t, *graph, meta);
    check_rasters(t, meta);
    if (m_.ladder) ladder_.push_back(ladder_facts(t, shard, meta, graph_doc));
  }

  // The schema's findings, then the reader's (a range or rule the schema cannot state)
  // when the schema found nothing: one problem is reported once.
  std::optional<io::TileMeta> read_meta(const io::DatasetTile& t, const json& doc) {
    const std::string subject = t.shard + "/" + t.key + ".meta.json";
    if (meta_schema_) {
      const Issues schema = meta_schema_->validate(doc, subject, "meta.schema");
      issues_.append(schema);
      if (!schema.empty()) return std::nullopt;
    }
    try {
      return io::tile_meta_from_json(doc, subject);
    } catch (const Error& e) {
      error("meta.schema", subject + ":" + e.record(), e.expected());
      return std::nullopt;
    }
  }

  void check_meta(const io::DatasetTile& t, const io::TileMeta& meta, const io::ShardEntry& shard) {
    const std::string subject = t.shard + "/" + t.key + ".meta.json";
    if (meta.key != t.key) error("tile.key", subject + ":/key", "the member's key '" + t.key + "'");
    const auto expect = [&](const char* field, bool same, const std::string& want) {
      if (!same) error("meta.schema", subject + ":/" + field, "equal to " + want + " (shard / tile_format)");
    };
    expect("split", meta.split == shard.split, "\"" + shard.split + "\"");
    expect("location", meta.location == shard.location, "\"" + shard.location + "\"");
    expect("size_px", meta.size_px == size_px_, std::to_string(size_px_));
    expect("resolution_m", meta.resolution_m == res_m_, format_double(res_m_));
    const Rect r = rect_of(meta);
    const double extent = size_px_ * res_m_;
    if (!near(r.x_east - r.x_west, extent) || !near(r.y_north - r.y_south, extent))
      error("meta.schema", subject + ":/bounds_m",
            "a square of size_px * resolution_m = " + format_double(extent) + " m");
    // A rung tile repeats its split tile's crop: the split checks count split tiles only.
    if (shard.rung == 0) tiles_.push_back({t.key, meta.split, meta.location, t.shard, r});
  }

  // As read_meta: the schema first; the reader then lists every reference problem (an id
  // repeated, an edge or a lane change naming no node) and leaves those edges out.
  struct ReadGraph {
    graph::TileGraph graph;
    size_t edges_in_file = 0;
    // An edge or lane change the reader left out shifts the later ones' positions: their
    // own checks would name the wrong element, so they wait for the references' fix.
    bool all_edges = true, all_lane_changes = true;
  };
  std::optional<ReadGraph> read_graph(const io::DatasetTile& t, const json& doc) {
    const std::string subject = t.shard + "/" + t.key + ".graph.json";
    if (graph_schema_) {
      const Issues schema = graph_schema_->validate(doc, subject, "graph.schema");
      issues_.append(schema);
      if (!schema.empty()) return std::nullopt;  // the checks below assume the schema's shape
    }
    try {
      Issues references;
      ReadGraph out{io::tile_graph_from_json(doc, subject, &references), doc["edges"].size()};
      // A map-update tile's prior graph: its references too (paths under /prior).
      (void)io::tile_prior_graph_from_json(doc, subject, &references);
      for (const Issue& i : references.items()) error(i.check, i.subject, i.message);
      out.all_edges = out.graph.edges.size() == out.edges_in_file;
      out.all_lane_changes =
          !doc.contains("lane_changes") || out.graph.lane_changes.size() == doc["lane_changes"].size();
      if (str_of(doc, "key") != t.key) error("tile.key", subject + ":/key", "the member's key '" + t.key + "'");
      return out;
    } catch (const Error& e) {
      error("graph.schema", subject + ":" + e.record(), e.expected());
      return std::nullopt;
    }
  }

  void check_graph(const io::DatasetTile& t, const ReadGraph& read, const std::optional<io::TileMeta>& meta) {
    const std::string subject = t.shard + "/" + t.key + ".graph.json";
    const graph::TileGraph& g = read.graph;
    const auto n = static_cast<int64_t>(g.nodes.size());
    for (int64_t i = 0; i < n; ++i) {
      const graph::TileNode& node = g.nodes[static_cast<size_t>(i)];
      const std::string at = subject + ":/nodes/" + std::to_string(i);
      if (node.id != i)
        error("graph.indices", at + "/id",
              "id " + std::to_string(i) + " (its position), got " + std::to_string(node.id));
      if (meta) check_node_place(node, rect_of(*meta), at);
    }
    std::set<std::pair<int32_t, int32_t>> seen;
    for (size_t k = 0; read.all_edges && k < g.edges.size(); ++k) {
      const graph::TileEdge& e = g.edges[k];
      const std::string at = subject + ":/edges/" + std::to_string(k);
      if (e.source == e.target)
        error("graph.self_loops", at, "an edge between two nodes, got a self-loop on node " + std::to_string(e.source));
      if (!seen.insert({e.source, e.target}).second)
        error("graph.duplicates", at, strprintf("a single edge %d -> %d", e.source, e.target));
      const double len = distance_m(g, e.source, e.target);
      if (len > max_spacing_m_ + o_.length_tolerance_m)
        error(
            "graph.edge_length", at,
            "at most graph.max_spacing_m = " + format_double(max_spacing_m_) + " m, got " + format_double(len) + " m");
    }
    if (read.all_lane_changes) check_lane_changes(g, subject);
    if (!meta) return;
    if (meta->nodes != n)
      error("meta.counts", t.shard + "/" + t.key + ".meta.json:/counts/nodes",
            strprintf("%lld (graph.json)", static_cast<long long>(n)));
    // Edges the reader left out (their ends name no node) still count: the file has them.
    if (meta->edges != static_cast<int64_t>(read.edges_in_file))
      error("meta.counts", t.shard + "/" + t.key + ".meta.json:/counts/edges",
            strprintf("%zu (graph.json)", read.edges_in_file));
  }

  // A node inside the tile's bounds, its pixel coordinates those of its metres.
  void check_node_place(const graph::TileNode& node, const Rect& bounds, const std::string& at) {
    const double x = node.x_m, y = node.y_m, tol = o_.length_tolerance_m;
    if (x < bounds.x_west - tol || x > bounds.x_east + tol || y < bounds.y_south - tol || y > bounds.y_north + tol)
      error("graph.in_tile", at, "a node inside bounds_m, got x " + format_double(x) + ", y " + format_double(y));
    const double want_u = (x - bounds.x_west) / res_m_ - 0.5, want_v = (bounds.y_north - y) / res_m_ - 0.5;
    // Pixel tolerance: the metre tolerance in pixels plus rounding of the division.
    const double tol_px = tol / res_m_ + 1e-6;
    if (std::abs(node.u_px - want_u) > tol_px || std::abs(node.v_px - want_v) > tol_px)
      error(
          "graph.pixel_coords", at,
          strprintf("u, v = %s, %s from x, y; got %s, %s", format_double(want_u).c_str(), format_double(want_v).c_str(),
                    format_double(node.u_px).c_str(), format_double(node.v_px).c_str()));
  }

  // The optional lane_changes (the reader checked their ends): two different nodes, no
  // farther apart than the rule allows (the offset plus half a node spacing along the
  // lane, and the length tolerance).
  void check_lane_changes(const graph::TileGraph& g, const std::string& subject) {
    const double reach_m = std::hypot(graph::kLaneChangeMaxOffsetM, max_spacing_m_ / 2.0) + o_.length_tolerance_m;
    for (size_t k = 0; k < g.lane_changes.size(); ++k) {
      const graph::TileLaneChange& c = g.lane_changes[k];
      const std::string at = subject + ":/lane_changes/" + std::to_string(k);
      if (c.source == c.target) {
        error("graph.lane_changes", at, "two different nodes, got node " + std::to_string(c.source) + " twice");
        continue;
      }
      const double len = distance_m(g, c.source, c.target);
      if (len > reach_m)
        error("graph.lane_changes", at,
              "at most " + format_double(reach_m) + " m between its nodes, got " + format_double(len) + " m");
    }
  }

  std::optional<io::Raster> decode(const io::DatasetTile& t, const RasterSpec& spec,
                                   const std::optional<io::TileMeta>& meta) {
    const std::string subject = t.shard + "/" + t.key + "." + spec.suffix;
    io::GeoRef georef;
    io::Raster r;
    try {
      // The header first: a raster of the wrong size or type is reported without decoding
      // it, so a small file claiming a huge image allocates nothing.
      const io::RasterHeader h = io::read_geotiff_header(t.files.at(spec.suffix), subject);
      if (h.width != size_px_ || h.height != size_px_ || h.type != spec.type || h.bands != spec.bands) {
        r.width = h.width;
        r.height = h.height;
        r.bands = h.bands;
        r.type = h.type;
      } else {
        r = io::decode_geotiff(t.files.at(spec.suffix), subject, &georef);
      }
    } catch (const Error& e) {
      error("raster.readable", subject, e.what());
      return std::nullopt;
    }
    if (r.width != size_px_ || r.height != size_px_)
      error("raster.size", subject,
            strprintf("%d x %d pixels (tile_format.size_px), got %d x %d", size_px_, size_px_, r.width, r.height));
    if (r.type != spec.type || r.bands != spec.bands)
      error("raster.dtype", subject,
            strprintf("%s x %d, got %s x %d", spec.type == io::SampleType::kUInt8 ? "uint8" : "float32", spec.bands,
                      r.type == io::SampleType::kUInt8 ? "uint8" : "float32", r.bands));
    if (meta && !r.data.empty()) {  // decoded: its georeference was read
      const Rect bounds = rect_of(*meta);
      if (georef.location != meta->location)
        error("raster.georef", subject, "the CRS of location '" + meta->location + "', got '" + georef.location + "'");
      if (!near(georef.x_west_m, bounds.x_west) || !near(georef.y_north_m, bounds.y_north))
        error("raster.georef", subject,
              "north-west corner (" + format_double(bounds.x_west) + ", " + format_double(bounds.y_north) +
                  ") from meta bounds_m, got (" + format_double(georef.x_west_m) + ", " +
                  format_double(georef.y_north_m) + ")");
      if (std::abs(georef.resolution_m - res_m_) > 1e-9)
        error("raster.georef", subject,
              "pixel size " + format_double(res_m_) + " m, got " + format_double(georef.resolution_m));
    }
    const bool usable = r.width == size_px_ && r.height == size_px_ && r.type == spec.type && r.bands == spec.bands;
    return usable ? std::optional<io::Raster>(std::move(r)) : std::nullopt;
  }

  void check_rasters(const io::DatasetTile& t, const std::optional<io::TileMeta>& meta) {
    std::map<std::string, io::Raster> rasters;
    for (const RasterSpec& spec : raster_specs()) {
      if (!t.has(spec.suffix)) continue;
      if (std::optional<io::Raster> r = decode(t, spec, meta)) rasters.emplace(spec.suffix, std::move(*r));
    }
    const std::string base = t.shard + "/" + t.key;
    const size_t pixels = static_cast<size_t>(size_px_) * size_px_;
    const ReportFinding report = [this](const std::string& check, const std::string& subject,
                                        const std::string& message) { error(check, subject, message); };
    int64_t vehicle_px = -1;
    if (auto it = rasters.find("vehicle.tif"); it != rasters.end())
      vehicle_px = check_vehicle_values(it->second, pixels, base + ".vehicle.tif", report);
    check_coverage_values(rasters, pixels, base, meta, vehicle_px, report);
  }

  void check_split_disjoint() {
    // A time split (splits.preset before-after) puts both splits on the same streets.
    const nlohmann::ordered_json::json_pointer preset("/splits/preset");
    if (!on("split.disjoint") || (m_.config.contains(preset) && m_.config.at(preset) == "before-after")) return;
    const double tol = o_.length_tolerance_m;
    for (const io::ManifestLocation& loc : m_.locations)
      for (const io::Region& region : loc.regions) {
        const Rect r{region.bounds_m[0], region.bounds_m[1], region.bounds_m[2], region.bounds_m[3]};
        for (const TileRecord& t : tiles_)
          if (t.location == loc.name && t.split != region.split && overlaps(t.bounds, r, tol))
            error("split.disjoint", t.shard + "/" + t.key,
                  "a " + t.split + " tile outside " + region.split + " region '" + region.name + "'");
      }
    // Tiles of different splits: sweep in x_west order.
    std::vector<const TileRecord*> sorted;
    for (const TileRecord& t : tiles_) sorted.push_back(&t);
    std::sort(sorted.begin(), sorted.end(), [](const TileRecord* a, const TileRecord* b) {
      return a->bounds.x_west != b->bounds.x_west ? a->bounds.x_west < b->bounds.x_west : a->key < b->key;
    });
    for (size_t i = 0; i < sorted.size(); ++i)
      for (size_t j = i + 1; j < sorted.size() && sorted[j]->bounds.x_west < sorted[i]->bounds.x_east - tol; ++j) {
        const TileRecord& a = *sorted[i];
        const TileRecord& b = *sorted[j];
        if (a.location == b.location && a.split != b.split && overlaps(a.bounds, b.bounds, tol))
          error("split.disjoint", a.shard + "/" + a.key, "no overlap with " + b.split + " tile " + b.key);
      }
  }

  void check_split_counts() {
    if (!on("split.counts")) return;
    std::map<std::string, int64_t> split_tiles, split_shards;
    std::map<std::pair<std::string, std::string>, int64_t> location_tiles;
    for (const io::ShardEntry& shard : m_.shards) {
      const int64_t found = found_per_shard_[shard.name];
      if (shard.tiles != found)
        error("split.counts", shard.name + ":tiles",
              strprintf("%lld tiles found, manifest says %lld", static_cast<long long>(found),
                        static_cast<long long>(shard.tiles)));
      split_tiles[shard.split] += found;
      ++split_shards[shard.split];
      location_tiles[{shard.location, shard.split}] += found;
    }
    int64_t total = 0;
    for (const char* split : {"train", "val", "test"}) {
      total += split_tiles[split];
      const io::TileShardCount& listed = *m_.counts.of(split);
      if (listed.tiles != split_tiles[split])
        error("split.counts", std::string("manifest.json:/counts/") + split + "/tiles",
              strprintf("%lld tiles found", static_cast<long long>(split_tiles[split])));
      if (listed.shards != split_shards[split])
        error("split.counts", std::string("manifest.json:/counts/") + split + "/shards",
              strprintf("%lld shards listed", static_cast<long long>(split_shards[split])));
    }
    if (m_.counts.total_tiles != total)
      error("split.counts", "manifest.json:/counts/total_tiles",
            strprintf("%lld tiles found", static_cast<long long>(total)));
    for (const io::ManifestLocation& loc : m_.locations) {
      const std::pair<const char*, int64_t> listed[] = {
          {"train", loc.counts.train}, {"val", loc.counts.val}, {"test", loc.counts.test}};
      for (const auto& [split, n] : listed) {
        const int64_t found = location_tiles[{loc.name, split}];
        if (n != found)
          error("split.counts", "manifest.json:/locations/" + loc.name + "/counts/" + split,
                strprintf("%lld tiles found, manifest says %lld", static_cast<long long>(found),
                          static_cast<long long>(n)));
      }
    }
  }

  const DatasetValidateOptions& o_;
  const io::Dataset& ds_;
  const io::Manifest& m_;
  json document_;
  fs::path schemas_;
  int size_px_ = 256;
  double res_m_ = 0.2;
  double max_spacing_m_ = 2.0;
  std::set<std::string> files_;
  std::optional<SchemaValidator> meta_schema_, graph_schema_;
  Issues issues_;
  std::set<std::string> keys_;
  std::vector<TileRecord> tiles_;
  std::map<std::string, int64_t> found_per_shard_;
  std::vector<LadderTileFacts> ladder_;  // every tile's facts, in a dataset with a ladder
};

}  // namespace

Issues validate_dataset(const DatasetValidateOptions& options) {
  options.validate();
  const fs::path schemas = find_schemas_dir(options.schemas_dir);
  const io::Dataset ds = io::Dataset::open(options.root);  // every field the model holds, checked
  const std::string manifest = ds.manifest_file();
  json document = io::parse_manifest_text(io::read_manifest_text(manifest), manifest);
  return DatasetChecker(options, ds, std::move(document), schemas).run();
}

}  // namespace nsg::validate
