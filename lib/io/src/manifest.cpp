#include "nsg/io/manifest.h"

#include <cmath>
#include <regex>
#include <system_error>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/strings.h"
#include "nsg/io/tile_meta.h"

namespace nsg::io {

namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

// ---- field readers: each names the file, the JSON pointer and what was expected ----------

// A key as a JSON pointer token (RFC 6901: '~' → "~0", '/' → "~1").
std::string token(const std::string& key) {
  std::string out;
  for (char c : key) out += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return out;
}

std::string child(const std::string& at, const std::string& name) { return at + "/" + token(name); }
std::string child(const std::string& at, size_t i) { return at + "/" + std::to_string(i); }

void need_object(const ordered_json& j, const std::string& file, const std::string& at, const std::string& what) {
  NSG_CHECK(j.is_object(), ParseError, file, at, what);
}

const ordered_json& member(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  NSG_CHECK(obj.is_object() && obj.contains(name), ParseError, file, child(at, name),
            "a field '" + std::string(name) + "'");
  return obj[name];
}

std::string text(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  const ordered_json& v = member(obj, name, file, at);
  NSG_CHECK(v.is_string(), ParseError, file, child(at, name), "a string");
  return v.get<std::string>();
}

// A name: a non-empty string.
std::string name_text(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  std::string s = text(obj, name, file, at);
  NSG_CHECK(!s.empty(), ParseError, file, child(at, name), "a non-empty string");
  return s;
}

// An integer in [lo, hi] (a count, a rung): not a float, not negative.
int64_t integer_in(const ordered_json& v, int64_t lo, int64_t hi, const std::string& file, const std::string& at) {
  const bool in_range =
      (v.is_number_unsigned() && v.get<uint64_t>() <= static_cast<uint64_t>(hi) && v.get<int64_t>() >= lo) ||
      (v.is_number_integer() && !v.is_number_unsigned() && v.get<int64_t>() >= lo && v.get<int64_t>() <= hi);
  NSG_CHECK(in_range, ParseError, file, at,
            "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" +
                (v.is_number() ? ", got " + v.dump() : ""));
  return v.get<int64_t>();
}

int64_t count(const ordered_json& obj, const char* name, int64_t hi, const std::string& file, const std::string& at) {
  return integer_in(member(obj, name, file, at), 0, hi, file, child(at, name));
}

std::string split_name(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  const std::string s = text(obj, name, file, at);
  NSG_CHECK(s == "train" || s == "val" || s == "test", ParseError, file, child(at, name),
            "train, val or test, got '" + printable_text(s) + "'");
  return s;
}

std::string sha256_text(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  const std::string s = text(obj, name, file, at);
  const bool hex = s.size() == 64 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
  NSG_CHECK(hex, ParseError, file, child(at, name), "a sha256: 64 lowercase hex digits");
  return s;
}

// A location's name: readers make file names of it (preview's overview-<location>.png) and
// keys begin with it, so letters, digits, '-' and '_' only (keys hold no dots).
std::string location_name(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  const std::string s = name_text(obj, name, file, at);
  const bool safe =
      s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_") == std::string::npos;
  NSG_CHECK(safe, ParseError, file, child(at, name),
            "a location name of letters, digits, '-' and '_', got '" + printable_text(s) + "'");
  return s;
}

// A shard's name: <split>-NNNNNN, or <split>-r<rung>-NNNNNN for a rung shard (the preview
// names its mosaic <shard>.png; the name must be the split's).
void check_shard_name(const std::string& shard, const std::string& split, int rung, const std::string& file,
                      const std::string& at) {
  static const std::regex kName(R"((train|val|test)(-r([1-9][0-9]{0,5}))?-[0-9]{6})");
  std::smatch m;
  const bool ok = std::regex_match(shard, m, kName) && m[1] == split &&
                  (rung == 0 ? !m[2].matched : m[2].matched && m[3] == std::to_string(rung));
  NSG_CHECK(ok, ParseError, file, at,
            (rung == 0 ? "a shard name " + split + "-NNNNNN"
                       : "a rung shard name " + split + "-r" + std::to_string(rung) + "-NNNNNN") +
                ", got '" + printable_text(shard) + "'");
}

// A path relative to the dataset that stays inside it: the readers open it.
std::string inside_path(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  const std::string s = text(obj, name, file, at);
  NSG_CHECK(stays_inside(s), ParseError, file, child(at, name),
            "a relative path inside the dataset folder, got '" + printable_text(s) + "'");
  return s;
}

// An array of at most kMaxManifestEntries entries.
const ordered_json& list(const ordered_json& obj, const char* name, const std::string& file, const std::string& at) {
  const ordered_json& v = member(obj, name, file, at);
  NSG_CHECK(v.is_array(), ParseError, file, child(at, name), "an array");
  NSG_CHECK(static_cast<int64_t>(v.size()) <= kMaxManifestEntries, ParseError, file, child(at, name),
            "at most " + std::to_string(kMaxManifestEntries) + " entries, got " + std::to_string(v.size()));
  return v;
}

std::vector<std::string> strings(const ordered_json& obj, const char* name, const std::string& file,
                                 const std::string& at) {
  const ordered_json& v = list(obj, name, file, at);
  std::vector<std::string> out;
  for (size_t i = 0; i < v.size(); ++i) {
    NSG_CHECK(v[i].is_string() && !v[i].get<std::string>().empty(), ParseError, file, child(child(at, name), i),
              "a non-empty string");
    out.push_back(v[i].get<std::string>());
  }
  return out;
}

// ---- parts ------------------------------------------------------------------------------

// `inside`: the file is one of the dataset's (maps), so it must stay inside it.
FileRecord file_record(const ordered_json& j, bool inside, const std::string& file, const std::string& at) {
  need_object(j, file, at, "a file record {file, sha256, bytes}");
  FileRecord r;
  r.file = inside ? inside_path(j, "file", file, at) : name_text(j, "file", file, at);
  r.sha256 = sha256_text(j, "sha256", file, at);
  r.bytes = count(j, "bytes", kMaxManifestFileBytes, file, at);
  return r;
}

ManifestInputs inputs_from_json(const ordered_json& j, const std::string& file, const std::string& at) {
  need_object(j, file, at, "the run's inputs {dataroot, version, tables, map_expansion, detections}");
  ManifestInputs in;
  in.dataroot = text(j, "dataroot", file, at);
  in.version = text(j, "version", file, at);
  const ordered_json& tables = list(j, "tables", file, at);
  for (size_t i = 0; i < tables.size(); ++i)
    in.tables.push_back(file_record(tables[i], false, file, child(child(at, "tables"), i)));
  const ordered_json& maps = member(j, "map_expansion", file, at);
  const std::string maps_at = child(at, "map_expansion");
  NSG_CHECK(maps.is_object() && static_cast<int64_t>(maps.size()) <= kMaxManifestEntries, ParseError, file, maps_at,
            "an object of map files by location");
  for (const auto& [location, record] : maps.items()) {
    const std::string record_at = child(maps_at, location);
    MapExpansionRecord m{location, file_record(record, false, file, record_at),
                         text(record, "version", file, record_at)};
    in.map_expansion.push_back(std::move(m));
  }
  const ordered_json& detections = member(j, "detections", file, at);
  if (!detections.is_null()) in.detections = file_record(detections, false, file, child(at, "detections"));
  return in;
}

TileFormat tile_format_from_json(const ordered_json& j, const std::string& file, const std::string& at) {
  need_object(j, file, at, "the tile format {resolution_m, size_px, key_pattern, files}");
  TileFormat f;
  const ordered_json& res = member(j, "resolution_m", file, at);
  constexpr double kMaxResolutionM = 100.0;  // as the tile meta's reader
  NSG_CHECK(res.is_number() && std::isfinite(res.get<double>()) && res.get<double>() > 0 &&
                res.get<double>() <= kMaxResolutionM,
            ParseError, file, child(at, "resolution_m"), "a resolution in (0, 100] metres per pixel");
  f.resolution_m = res.get<double>();
  f.size_px =
      static_cast<int>(integer_in(member(j, "size_px", file, at), 1, kMaxTileSizePx, file, child(at, "size_px")));
  f.key_pattern = text(j, "key_pattern", file, at);
  f.files = strings(j, "files", file, at);
  return f;
}

TileShardCount tile_shard_count(const ordered_json& j, const std::string& file, const std::string& at) {
  need_object(j, file, at, "{tiles, shards}");
  return {count(j, "tiles", kMaxManifestTiles, file, at), count(j, "shards", kMaxManifestEntries, file, at)};
}

ManifestCounts counts_from_json(const ordered_json& j, const std::string& file, const std::string& at) {
  need_object(j, file, at, "the tile and shard counts per split");
  ManifestCounts c;
  c.train = tile_shard_count(member(j, "train", file, at), file, child(at, "train"));
  c.val = tile_shard_count(member(j, "val", file, at), file, child(at, "val"));
  c.test = tile_shard_count(member(j, "test", file, at), file, child(at, "test"));
  c.total_tiles = count(j, "total_tiles", kMaxManifestTiles, file, at);
  return c;
}

// A shard's file (tar layout) or folder (folder layout), whichever the layout reads.
ShardEntry shard_from_json(const ordered_json& j, Layout layout, bool rung, const std::string& file,
                           const std::string& at) {
  need_object(j, file, at, "a shard entry");
  ShardEntry s;
  s.name = name_text(j, "name", file, at);
  s.split = split_name(j, "split", file, at);
  s.location = location_name(j, "location", file, at);
  s.tiles = count(j, "tiles", kMaxManifestTiles, file, at);
  s.first_key = text(j, "first_key", file, at);
  s.last_key = text(j, "last_key", file, at);
  if (layout == Layout::kTar) s.file = inside_path(j, "file", file, at);
  else s.folder = inside_path(j, "folder", file, at);
  s.sha256 = sha256_text(j, "sha256", file, at);
  s.bytes = count(j, "bytes", kMaxManifestFileBytes, file, at);
  if (rung) s.rung = static_cast<int>(integer_in(member(j, "rung", file, at), 1, kMaxRung, file, child(at, "rung")));
  check_shard_name(s.name, s.split, s.rung, file, child(at, "name"));
  return s;
}

std::vector<ShardEntry> shards_from_json(const ordered_json& obj, Layout layout, bool rung, const std::string& file,
                                         const std::string& at) {
  const ordered_json& v = list(obj, "shards", file, at);
  std::vector<ShardEntry> out;
  out.reserve(v.size());
  for (size_t i = 0; i < v.size(); ++i)
    out.push_back(shard_from_json(v[i], layout, rung, file, child(child(at, "shards"), i)));
  return out;
}

// A rung: 1 … kMaxRung, or "all" (kRungAll) where `all` allows it.
int rung_from_json(const ordered_json& v, bool all, const std::string& file, const std::string& at) {
  if (all && v.is_string() && v.get<std::string>() == "all") return kRungAll;
  return static_cast<int>(integer_in(v, 1, kMaxRung, file, at));
}

Ladder ladder_from_json(const ordered_json& j, Layout layout, const std::string& file, const std::string& at) {
  need_object(j, file, at, "the observation ladder {rungs, order, splits, counts, shards}");
  Ladder l;
  const ordered_json& rungs = list(j, "rungs", file, at);
  for (size_t i = 0; i < rungs.size(); ++i)
    l.rungs.push_back(rung_from_json(rungs[i], true, file, child(child(at, "rungs"), i)));
  l.order = text(j, "order", file, at);
  NSG_CHECK(l.order == "time" || l.order == "seeded", ParseError, file, child(at, "order"), "time or seeded");
  const ordered_json& splits = list(j, "splits", file, at);
  for (size_t i = 0; i < splits.size(); ++i) {
    const std::string split_at = child(child(at, "splits"), i);
    NSG_CHECK(splits[i].is_string(), ParseError, file, split_at, "train, val or test");
    const std::string s = splits[i].get<std::string>();
    NSG_CHECK(s == "train" || s == "val" || s == "test", ParseError, file, split_at, "train, val or test");
    l.splits.push_back(s);
  }
  const ordered_json& counts = member(j, "counts", file, at);
  const std::string counts_at = child(at, "counts");
  NSG_CHECK(counts.is_object() && static_cast<int64_t>(counts.size()) <= kMaxManifestEntries, ParseError, file,
            counts_at, "an object of counts by rung");
  for (const auto& [key, value] : counts.items()) {
    const std::string rung_at = child(counts_at, key);
    const bool decimal =
        !key.empty() && key.size() <= 6 && key.find_first_not_of("0123456789") == std::string::npos && key[0] != '0';
    NSG_CHECK(decimal && std::stoi(key) <= kMaxRung, ParseError, file, rung_at,
              "a rung (1 … " + std::to_string(kMaxRung) + ") as the key");
    l.counts.emplace_back(std::stoi(key), tile_shard_count(value, file, rung_at));
  }
  l.shards = shards_from_json(j, layout, true, file, at);
  return l;
}

PlannedShardEntry planned_shard(const ordered_json& j, bool rung, const std::string& file, const std::string& at) {
  need_object(j, file, at, "a planned shard");
  PlannedShardEntry s;
  s.name = name_text(j, "name", file, at);
  s.split = split_name(j, "split", file, at);
  if (rung) s.rung = static_cast<int>(integer_in(member(j, "rung", file, at), 1, kMaxRung, file, child(at, "rung")));
  s.tiles = count(j, "tiles", kMaxManifestTiles, file, at);
  s.first_key = text(j, "first_key", file, at);
  s.last_key = text(j, "last_key", file, at);
  check_shard_name(s.name, s.split, s.rung, file, child(at, "name"));
  return s;
}

std::vector<PlannedShardEntry> planned_shards(const ordered_json& obj, const char* name, bool rung,
                                              const std::string& file, const std::string& at) {
  const ordered_json& v = list(obj, name, file, at);
  std::vector<PlannedShardEntry> out;
  for (size_t i = 0; i < v.size(); ++i) out.push_back(planned_shard(v[i], rung, file, child(child(at, name), i)));
  return out;
}

// A scene left out: {name, reason}, and its location in the manifest's own list.
ExcludedScene excluded_scene(const ordered_json& j, bool with_location, const std::string& file,
                             const std::string& at) {
  need_object(j, file, at, "an excluded scene {name, reason}");
  ExcludedScene e;
  e.name = name_text(j, "name", file, at);
  if (with_location) e.location = name_text(j, "location", file, at);
  e.reason = text(j, "reason", file, at);
  return e;
}

std::vector<ExcludedScene> excluded_scenes(const ordered_json& obj, const char* name, bool with_location,
                                           const std::string& file, const std::string& at) {
  const ordered_json& v = list(obj, name, file, at);
  std::vector<ExcludedScene> out;
  for (size_t i = 0; i < v.size(); ++i)
    out.push_back(excluded_scene(v[i], with_location, file, child(child(at, name), i)));
  return out;
}

ManifestLocation location_from_json(const ordered_json& j, const std::string& file, const std::string& at) {
  need_object(j, file, at, "a location's plan");
  ManifestLocation loc;
  loc.name = location_name(j, "name", file, at);
  loc.map_version = text(j, "map_version", file, at);
  const ordered_json& graph = member(j, "lane_graph", file, at);
  const std::string graph_at = child(at, "lane_graph");
  need_object(graph, file, graph_at, "the lane graph's counts {nodes, edges, lanes, map_defects}");
  constexpr int64_t kMaxGraphCount = int64_t{1} << 40;
  loc.lane_graph = {count(graph, "nodes", kMaxGraphCount, file, graph_at),
                    count(graph, "edges", kMaxGraphCount, file, graph_at),
                    count(graph, "lanes", kMaxGraphCount, file, graph_at),
                    count(graph, "map_defects", kMaxGraphCount, file, graph_at)};
  if (j.contains("scenes")) {
    const ordered_json& scenes = j["scenes"];
    const std::string scenes_at = child(at, "scenes");
    need_object(scenes, file, scenes_at, "the location's scenes {used, excluded}");
    loc.scenes = LocationScenes{count(scenes, "used", kMaxManifestEntries, file, scenes_at),
                                excluded_scenes(scenes, "excluded", false, file, scenes_at)};
  }
  const ordered_json& regions = list(j, "regions", file, at);
  for (size_t k = 0; k < regions.size(); ++k)
    loc.regions.push_back(region_from_json(regions[k], file, child(child(at, "regions"), k)));
  const ordered_json& counts = member(j, "counts", file, at);
  const std::string counts_at = child(at, "counts");
  need_object(counts, file, counts_at, "the location's tiles per split {train, val, test}");
  loc.counts = {count(counts, "train", kMaxManifestTiles, file, counts_at),
                count(counts, "val", kMaxManifestTiles, file, counts_at),
                count(counts, "test", kMaxManifestTiles, file, counts_at)};
  loc.shards = planned_shards(j, "shards", false, file, at);
  if (j.contains("time_split")) loc.time_split = j["time_split"];
  if (j.contains("map_update")) loc.map_update = j["map_update"];
  if (j.contains("rung_shards")) loc.rung_shards = planned_shards(j, "rung_shards", true, file, at);
  return loc;
}

// Kept as written when present (the schema check judges them); null when absent.
ordered_json optional_part(const ordered_json& doc, const char* name) {
  return doc.contains(name) ? doc[name] : ordered_json();
}

Layout layout_from_json(const ordered_json& doc, const std::string& file) {
  const std::string layout = text(doc, "layout", file, "");
  NSG_CHECK(layout == "tar" || layout == "folder", ParseError, file, "/layout",
            "tar or folder, got '" + printable_text(layout) + "'");
  return layout == "tar" ? Layout::kTar : Layout::kFolder;
}

// ---- writer parts -------------------------------------------------------------------------

ordered_json file_record_json(const FileRecord& r) {
  return {{"file", r.file}, {"sha256", r.sha256}, {"bytes", r.bytes}};
}

ordered_json tile_shard_count_json(const TileShardCount& c) { return {{"tiles", c.tiles}, {"shards", c.shards}}; }

ordered_json inputs_json(const ManifestInputs& in) {
  ordered_json tables = ordered_json::array();
  for (const FileRecord& t : in.tables) tables.push_back(file_record_json(t));
  ordered_json maps = ordered_json::object();
  for (const MapExpansionRecord& m : in.map_expansion) {
    ordered_json record = file_record_json(m.file);
    record["version"] = m.version;
    maps[m.location] = std::move(record);
  }
  return {{"dataroot", in.dataroot},
          {"version", in.version},
          {"tables", std::move(tables)},
          {"map_expansion", std::move(maps)},
          {"detections", in.detections ? file_record_json(*in.detections) : ordered_json(nullptr)}};
}

ordered_json shard_json(const ShardEntry& s) {
  ordered_json j = {{"name", s.name},   {"split", s.split},         {"location", s.location},
                    {"tiles", s.tiles}, {"first_key", s.first_key}, {"last_key", s.last_key}};
  if (!s.file.empty()) j["file"] = s.file;
  else j["folder"] = s.folder;
  j["sha256"] = s.sha256;
  j["bytes"] = s.bytes;
  if (s.rung > 0) j["rung"] = s.rung;
  return j;
}

ordered_json shards_json(const std::vector<ShardEntry>& shards) {
  ordered_json out = ordered_json::array();
  for (const ShardEntry& s : shards) out.push_back(shard_json(s));
  return out;
}

ordered_json ladder_json(const Ladder& l) {
  ordered_json rungs = ordered_json::array();
  for (int r : l.rungs) rungs.push_back(r == kRungAll ? ordered_json("all") : ordered_json(r));
  ordered_json counts = ordered_json::object();
  for (const auto& [rung, c] : l.counts) counts[std::to_string(rung)] = tile_shard_count_json(c);
  return {{"rungs", std::move(rungs)},
          {"order", l.order},
          {"splits", l.splits},
          {"counts", std::move(counts)},
          {"shards", shards_json(l.shards)}};
}

ordered_json planned_shard_json(const PlannedShardEntry& s) {
  ordered_json j = {{"name", s.name}, {"split", s.split}};
  if (s.rung > 0) j["rung"] = s.rung;
  j["tiles"] = s.tiles;
  j["first_key"] = s.first_key;
  j["last_key"] = s.last_key;
  return j;
}

ordered_json excluded_json(const std::vector<ExcludedScene>& scenes, bool with_location) {
  ordered_json out = ordered_json::array();
  for (const ExcludedScene& e : scenes)
    out.push_back(with_location ? ordered_json{{"name", e.name}, {"location", e.location}, {"reason", e.reason}}
                                : ordered_json{{"name", e.name}, {"reason", e.reason}});
  return out;
}

}  // namespace

// ---- the model's look-ups -------------------------------------------------------------------

const MapExpansionRecord* ManifestInputs::map_of(const std::string& location) const {
  for (const MapExpansionRecord& m : map_expansion)
    if (m.location == location) return &m;
  return nullptr;
}

const TileShardCount* ManifestCounts::of(const std::string& split) const {
  return split == "train" ? &train : split == "val" ? &val : split == "test" ? &test : nullptr;
}

const ManifestLocation* Manifest::location(const std::string& name) const {
  for (const ManifestLocation& l : locations)
    if (l.name == name) return &l;
  return nullptr;
}

// ---- the reader -----------------------------------------------------------------------------

Region region_from_json(const ordered_json& r, const std::string& file, const std::string& at) {
  need_object(r, file, at, "a region {name, split, bounds_m}");
  Region out;
  out.name = name_text(r, "name", file, at);
  out.split = split_name(r, "split", file, at);
  out.bounds_m = bounds_from_json(nlohmann::json(member(r, "bounds_m", file, at)), file, child(at, "bounds_m"));
  return out;
}

std::vector<ManifestLocation> manifest_locations_from_json(const ordered_json& locations, const std::string& file,
                                                           const std::string& at) {
  NSG_CHECK(locations.is_array() && static_cast<int64_t>(locations.size()) <= kMaxManifestEntries, ParseError, file, at,
            "an array of locations");
  std::vector<ManifestLocation> out;
  for (size_t i = 0; i < locations.size(); ++i) out.push_back(location_from_json(locations[i], file, child(at, i)));
  return out;
}

Manifest manifest_from_json(const ordered_json& doc, const std::string& file) {
  need_object(doc, file, "", "a dataset manifest (an object)");
  Manifest m;
  m.schema_version = text(doc, "schema_version", file, "");
  NSG_CHECK(m.schema_version == "1", ParseError, file, "/schema_version",
            "\"1\" (this nsgraph reads schema v1), got '" + printable_text(m.schema_version) + "'");
  m.tool = optional_part(doc, "tool");
  m.licence = optional_part(doc, "licence");
  const ordered_json& seed = member(doc, "seed", file, "");
  NSG_CHECK(seed.is_number_unsigned(), ParseError, file, "/seed", "an unsigned integer");
  m.seed = seed.get<uint64_t>();
  m.config = member(doc, "config", file, "");
  need_object(m.config, file, "/config", "the run's resolved config (an object)");
  m.inputs = inputs_from_json(member(doc, "inputs", file, ""), file, "/inputs");
  m.georeference = optional_part(doc, "georeference");
  m.layout = layout_from_json(doc, file);
  m.tile_format = tile_format_from_json(member(doc, "tile_format", file, ""), file, "/tile_format");
  m.locations = manifest_locations_from_json(member(doc, "locations", file, ""), file, "/locations");
  if (doc.contains("excluded_scenes")) m.excluded_scenes = excluded_scenes(doc, "excluded_scenes", true, file, "");
  m.counts = counts_from_json(member(doc, "counts", file, ""), file, "/counts");
  m.shards = shards_from_json(doc, m.layout, false, file, "");
  const ordered_json& maps = list(doc, "maps", file, "");
  for (size_t i = 0; i < maps.size(); ++i) m.maps.push_back(file_record(maps[i], true, file, child("/maps", i)));
  if (doc.contains("ladder")) m.ladder = ladder_from_json(doc["ladder"], m.layout, file, "/ladder");
  return m;
}

Manifest manifest_from_json(const nlohmann::json& doc, const std::string& file) {
  return manifest_from_json(ordered_json(doc), file);
}

namespace {

// Why a folder has no manifest.json, from what it holds instead, and what to do.
std::string missing_manifest(const fs::path& path) {
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::error_code ec;
  bool release = false;
  if (fs::is_directory(dir, ec))
    for (const auto& e : fs::directory_iterator(dir, ec))
      release = release || starts_with(e.path().filename().string(), "v1.0-");
  if (release)
    return "no manifest.json: this folder looks like a nuScenes release (it holds v1.0-…), not a dataset; make "
           "one with `nsgraph generate --dataroot " +
           dir.string() + " --out DATASET` and give DATASET";
  if (fs::is_directory(dir / "parts", ec))
    return "no manifest.json: an unfinished generate run (parts/ is there); rerun the same generate command, or "
           "`nsgraph merge --out " +
           dir.string() + "` once every share has finished";
  return "no manifest.json (expected a dataset made by `nsgraph generate`: give the folder that holds manifest.json)";
}

}  // namespace

std::string read_manifest_text(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  NSG_CHECK(fs::exists(status), IoError, path.string(), "", missing_manifest(path));
  // A device or FIFO (a link to /dev/zero) has no size to check and would be read forever.
  NSG_CHECK(fs::is_regular_file(status), ParseError, path.string(), "", "a regular file (the dataset manifest)");
  const uintmax_t bytes = fs::file_size(path, ec);
  NSG_CHECK(ec || bytes <= static_cast<uintmax_t>(kMaxManifestBytes), ParseError, path.string(), "",
            "a manifest of at most " + std::to_string(kMaxManifestBytes >> 20) + " MiB, got " + std::to_string(bytes) +
                " bytes");
  std::string text = read_file(path);  // IoError naming it when missing or unreadable
  // Grown since the size check (or not a regular file): the bound still holds.
  NSG_CHECK(static_cast<int64_t>(text.size()) <= kMaxManifestBytes, ParseError, path.string(), "",
            "a manifest of at most " + std::to_string(kMaxManifestBytes >> 20) + " MiB");
  return text;
}

nlohmann::json parse_manifest_text(std::string_view text, const std::string& file) {
  return parse_json_strict(text, file, "the dataset manifest", kMaxManifestDepth);
}

Manifest manifest_from_text(std::string_view text, const std::string& file) {
  parse_manifest_text(text, file);  // nesting and repeated keys; then in key order
  return manifest_from_json(ordered_json::parse(text), file);
}

Manifest read_manifest(const fs::path& path) { return manifest_from_text(read_manifest_text(path), path.string()); }

// ---- the writer -----------------------------------------------------------------------------

nlohmann::ordered_json region_to_json(const Region& r) {
  return {{"name", r.name}, {"split", r.split}, {"bounds_m", r.bounds_m}};
}

ordered_json location_to_json(const ManifestLocation& l) {
  ordered_json regions = ordered_json::array();
  for (const Region& r : l.regions) regions.push_back(region_to_json(r));
  ordered_json shards = ordered_json::array();
  for (const PlannedShardEntry& s : l.shards) shards.push_back(planned_shard_json(s));
  ordered_json doc = {{"name", l.name},
                      {"map_version", l.map_version},
                      {"lane_graph",
                       {{"nodes", l.lane_graph.nodes},
                        {"edges", l.lane_graph.edges},
                        {"lanes", l.lane_graph.lanes},
                        {"map_defects", l.lane_graph.map_defects}}}};
  if (l.scenes) doc["scenes"] = {{"used", l.scenes->used}, {"excluded", excluded_json(l.scenes->excluded, false)}};
  doc["regions"] = std::move(regions);
  doc["counts"] = {{"train", l.counts.train}, {"val", l.counts.val}, {"test", l.counts.test}};
  doc["shards"] = std::move(shards);
  if (!l.time_split.is_null()) doc["time_split"] = l.time_split;
  if (!l.map_update.is_null()) doc["map_update"] = l.map_update;
  if (l.rung_shards.empty()) return doc;
  ordered_json rung_shards = ordered_json::array();
  for (const PlannedShardEntry& s : l.rung_shards) rung_shards.push_back(planned_shard_json(s));
  doc["rung_shards"] = std::move(rung_shards);
  return doc;
}

fs::path release_folder(const ManifestInputs& inputs, const fs::path& dataset_root) {
  return resolve_document_path(inputs.dataroot, dataset_root);
}

ordered_json manifest_to_json(const Manifest& m) {
  ordered_json doc = {{"schema_version", m.schema_version}};
  if (!m.tool.is_null()) doc["tool"] = m.tool;
  if (!m.licence.is_null()) doc["licence"] = m.licence;
  doc["seed"] = m.seed;
  doc["config"] = m.config;
  doc["inputs"] = inputs_json(m.inputs);
  if (!m.georeference.is_null()) doc["georeference"] = m.georeference;
  doc["layout"] = m.tar_layout() ? "tar" : "folder";
  doc["tile_format"] = {{"resolution_m", m.tile_format.resolution_m},
                        {"size_px", m.tile_format.size_px},
                        {"key_pattern", m.tile_format.key_pattern},
                        {"files", m.tile_format.files}};
  ordered_json locations = ordered_json::array();
  for (const ManifestLocation& l : m.locations) locations.push_back(location_to_json(l));
  doc["locations"] = std::move(locations);
  if (m.excluded_scenes) doc["excluded_scenes"] = excluded_json(*m.excluded_scenes, true);
  ordered_json counts = {{"train", tile_shard_count_json(m.counts.train)},
                         {"val", tile_shard_count_json(m.counts.val)},
                         {"test", tile_shard_count_json(m.counts.test)},
                         {"total_tiles", m.counts.total_tiles}};
  doc["counts"] = std::move(counts);
  doc["shards"] = shards_json(m.shards);
  ordered_json maps = ordered_json::array();
  for (const FileRecord& f : m.maps) maps.push_back(file_record_json(f));
  doc["maps"] = std::move(maps);
  if (m.ladder) doc["ladder"] = ladder_json(*m.ladder);
  return doc;
}

std::string manifest_text(const Manifest& m) { return manifest_to_json(m).dump(1) + "\n"; }

}  // namespace nsg::io
