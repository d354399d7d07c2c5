// `nsgraph validate DATASET`: the clean e2e dataset has no problem; each deliberately
// corrupted copy fails with the expected check.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "generate_fixture.h"
#include "nsg/core/files.h"
#include "nsg/core/sha256.h"
#include "nsg/io/raster.h"
#include "nsg/io/tar.h"
#include "nsg/validate/dataset.h"
#include "nsg/validate/schema.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace nsg::test {
namespace {

using TileFiles = std::map<std::string, std::vector<uint8_t>>;  // suffix → bytes

json parse_bytes(const std::vector<uint8_t>& bytes) { return json::parse(bytes.begin(), bytes.end()); }
std::vector<uint8_t> to_bytes(const json& j) {
  const std::string s = j.dump();
  return {s.begin(), s.end()};
}

std::set<std::string> checks_of(const Issues& issues) {
  std::set<std::string> out;
  for (const Issue& i : issues.items()) out.insert(i.check);
  return out;
}

// A writable copy of the e2e dataset; edits keep it consistent except for the defect
// under test (the shard's sha256 and bytes are updated in the manifest).
class DatasetCopy {
 public:
  DatasetCopy() : root_(tmp_ / "dataset") {
    fs::copy(e2e_dataset(), root_, fs::copy_options::recursive);
    fs::remove_all(root_ / "parts");
  }
  const fs::path& root() const { return root_; }
  json manifest() const { return json::parse(read_file(root_ / "manifest.json")); }
  void write_manifest(const json& m) const { write_text(root_ / "manifest.json", m.dump(1)); }
  json shard(const std::string& split, size_t n = 0) const {
    const json m = manifest();
    for (const json& s : m["shards"])
      if (s["split"] == split && n-- == 0) return s;
    throw std::runtime_error("no such shard");
  }
  // Applies `edit` to tile `key` ("" = the shard's first tile) of shard `name`.
  std::string edit_tile(const std::string& name, std::string key, const std::function<void(TileFiles&)>& edit) const {
    json m = manifest();
    json* entry = nullptr;
    for (json& s : m["shards"])
      if (s["name"] == name) entry = &s;
    const fs::path path = root_ / (*entry)["file"].get<std::string>();
    std::vector<std::pair<std::string, TileFiles>> tiles;  // in member order
    std::vector<std::string> order;                        // suffix order of the first tile
    {
      io::TarReader reader(path);
      io::TarMember member;
      while (reader.next(member)) {
        const size_t dot = member.name.find('.');
        const std::string k = member.name.substr(0, dot), suffix = member.name.substr(dot + 1);
        if (tiles.empty() || tiles.back().first != k) tiles.push_back({k, {}});
        tiles.back().second[suffix] = member.bytes;
        if (tiles.size() == 1) order.push_back(suffix);
      }
    }
    if (key.empty()) key = tiles.front().first;
    io::TarWriter writer(path);
    for (auto& [k, files] : tiles) {
      if (k == key) edit(files);
      std::set<std::string> done;
      for (const std::string& suffix : order)
        if (files.count(suffix)) {
          writer.add(k + "." + suffix, files[suffix]);
          done.insert(suffix);
        }
      for (const auto& [suffix, bytes] : files)
        if (!done.count(suffix)) writer.add(k + "." + suffix, bytes);
    }
    const io::TarWriter::Result r = writer.finish();
    (*entry)["sha256"] = r.sha256_hex;
    (*entry)["bytes"] = r.bytes;
    write_manifest(m);
    return key;
  }
  Issues validate(const std::string& checks = "*") const {
    validate::DatasetValidateOptions o;
    o.root = root_;
    o.checks = checks;
    return validate::validate_dataset(o);
  }

 private:
  TempDir tmp_{"validate"};
  fs::path root_;
};

// Every issue is of `check`, and there is at least one.
void expect_only(const Issues& issues, const std::string& check) {
  EXPECT_EQ(checks_of(issues), std::set<std::string>{check}) << issues.format();
}

// Re-encodes a raster of the tile with `change` applied to its pixels / georef.
void reencode(TileFiles& files, const std::string& suffix,
              const std::function<void(io::Raster&, io::GeoRef&)>& change) {
  io::GeoRef georef;
  io::Raster r = io::decode_geotiff(files.at(suffix), suffix, &georef);
  change(r, georef);
  io::GeoTiffOptions options;
  if (suffix == "vehicle.tif" && r.type == io::SampleType::kFloat32) options.nodata = -1.0;
  if (suffix == "lidar.tif" || suffix == "rgb.tif") options.nodata = 0.0;
  if (suffix == "semantic.tif") options.nodata = 255.0;
  files[suffix] = io::encode_geotiff(r, georef, options);
}

void edit_json(TileFiles& files, const std::string& suffix, const std::function<void(json&)>& change) {
  json j = parse_bytes(files.at(suffix));
  change(j);
  files[suffix] = to_bytes(j);
}

// Adds node(s) and edges to graph.json and updates meta counts to match.
void add_to_graph(TileFiles& files, const std::function<void(json& graph)>& change) {
  edit_json(files, "graph.json", change);
  const json g = parse_bytes(files.at("graph.json"));
  edit_json(files, "meta.json", [&](json& meta) {
    meta["counts"]["nodes"] = g["nodes"].size();
    meta["counts"]["edges"] = g["edges"].size();
  });
}

json node_at(const json& meta, int64_t id, double x, double y) {
  const double x_west = meta["bounds_m"][0], y_north = meta["bounds_m"][3], res = meta["resolution_m"];
  return {{"id", id}, {"u", (x - x_west) / res - 0.5}, {"v", (y_north - y) / res - 0.5}, {"x", x}, {"y", y}};
}

TEST(ValidateDataset, CleanDatasetHasNoProblems) {
  validate::DatasetValidateOptions o;
  o.root = e2e_dataset();
  const Issues issues = validate::validate_dataset(o);
  EXPECT_TRUE(issues.empty()) << issues.format();
}

TEST(ValidateDataset, ChecksHaveDottedUniqueNames) {
  std::set<std::string> names;
  for (const validate::CheckInfo& c : validate::dataset_checks()) {
    EXPECT_NE(c.name.find('.'), std::string::npos) << c.name;
    EXPECT_FALSE(c.description.empty()) << c.name;
    EXPECT_TRUE(names.insert(c.name).second) << c.name;
  }
  EXPECT_GE(names.size(), 20u);
  for (const char* want :
       {"manifest.schema", "shard.sha256", "shard.members", "raster.size", "raster.dtype", "raster.nodata",
        "raster.georef", "graph.schema", "graph.indices", "graph.edge_length", "graph.in_tile", "graph.self_loops",
        "graph.duplicates", "graph.lane_changes", "split.disjoint", "split.counts", "determinism.config"})
    EXPECT_TRUE(names.count(want)) << want;
  EXPECT_TRUE(validate::check_selected("graph.*,shard.sha256", "graph.in_tile"));
  EXPECT_TRUE(validate::check_selected("graph.*,shard.sha256", "shard.sha256"));
  EXPECT_FALSE(validate::check_selected("graph.*,shard.sha256", "shard.members"));
}

TEST(ValidateDataset, FlippedByteInShard) {
  DatasetCopy d;
  const fs::path path = d.root() / d.shard("test")["file"].get<std::string>();
  std::string bytes = read_file(path);
  bytes[bytes.size() / 2] ^= 0x5a;
  write_text(path, bytes);
  EXPECT_TRUE(checks_of(d.validate()).count("shard.sha256"));
  // Only the hash check selected: that one problem and nothing else.
  expect_only(d.validate("shard.sha256"), "shard.sha256");
}

TEST(ValidateDataset, MissingMember) {
  DatasetCopy d;
  d.edit_tile(d.shard("train")["name"], "", [](TileFiles& f) { f.erase("vehicle.tif"); });
  const Issues issues = d.validate();
  expect_only(issues, "shard.members");
  EXPECT_NE(issues.items().at(0).subject.find("vehicle.tif"), std::string::npos);
}

TEST(ValidateDataset, UnexpectedMember) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) { f["extra.bin"] = {1, 2, 3}; });
  expect_only(d.validate(), "shard.members");
}

TEST(ValidateDataset, TileMovedIntoOtherSplitsRegion) {
  DatasetCopy d;
  // Move a train tile (train-west region, x 30..110) by +150 m into test-east; rasters,
  // graph and meta move together so only the split check can notice.
  const double dx = 150.0;
  d.edit_tile(d.shard("train")["name"], "", [&](TileFiles& f) {
    for (const char* s : {"lidar.tif", "rgb.tif", "semantic.tif", "vehicle.tif", "coverage.tif"})
      reencode(f, s, [&](io::Raster&, io::GeoRef& g) { g.x_west_m += dx; });
    edit_json(f, "graph.json", [&](json& g) {
      for (json& n : g["nodes"]) n["x"] = n["x"].get<double>() + dx;
    });
    edit_json(f, "meta.json", [&](json& m) {
      m["bounds_m"][0] = m["bounds_m"][0].get<double>() + dx;
      m["bounds_m"][2] = m["bounds_m"][2].get<double>() + dx;
    });
  });
  expect_only(d.validate(), "split.disjoint");
}

TEST(ValidateDataset, GraphNodeOutsideTile) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    const json meta = parse_bytes(f.at("meta.json"));
    add_to_graph(f, [&](json& g) {
      g["nodes"].push_back(node_at(meta, g["nodes"].size(), meta["bounds_m"][2].get<double>() + 5.0,
                                   meta["bounds_m"][1].get<double>() + 1.0));
    });
  });
  expect_only(d.validate(), "graph.in_tile");
}

TEST(ValidateDataset, EdgeOfThreeMetres) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    const json meta = parse_bytes(f.at("meta.json"));
    add_to_graph(f, [&](json& g) {
      const double x0 = meta["bounds_m"][0].get<double>() + 2.0, y0 = meta["bounds_m"][1].get<double>() + 2.0;
      const int64_t a = g["nodes"].size();
      g["nodes"].push_back(node_at(meta, a, x0, y0));
      g["nodes"].push_back(node_at(meta, a + 1, x0 + 3.0, y0));
      g["edges"].push_back({{"source", a}, {"target", a + 1}, {"lane_token", "x"}});
    });
  });
  const Issues issues = d.validate();
  expect_only(issues, "graph.edge_length");
  EXPECT_NE(issues.format().find("got 3.0 m"), std::string::npos) << issues.format();
}

TEST(ValidateDataset, SelfLoop) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    add_to_graph(f, [&](json& g) { g["edges"].push_back({{"source", 0}, {"target", 0}, {"lane_token", "x"}}); });
  });
  expect_only(d.validate(), "graph.self_loops");
}

TEST(ValidateDataset, DuplicateEdge) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "",
              [&](TileFiles& f) { add_to_graph(f, [&](json& g) { g["edges"].push_back(g["edges"][0]); }); });
  expect_only(d.validate(), "graph.duplicates");
}

TEST(ValidateDataset, LaneChangeToItselfOrTooFar) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    add_to_graph(f, [&](json& g) {
      // A lane change from node 0 to itself, and one to the node farthest from it.
      const json& nodes = g["nodes"];
      size_t far = 0;
      double far_m = 0.0;
      for (size_t k = 0; k < nodes.size(); ++k) {
        const double m = std::hypot(nodes[k]["x"].get<double>() - nodes[0]["x"].get<double>(),
                                    nodes[k]["y"].get<double>() - nodes[0]["y"].get<double>());
        if (m > far_m) std::tie(far, far_m) = std::make_tuple(k, m);
      }
      ASSERT_GT(far_m, 10.0);
      g["lane_changes"].push_back({{"source", 0}, {"target", 0}, {"from_lane_token", "a"}, {"to_lane_token", "b"}});
      g["lane_changes"].push_back({{"source", 0}, {"target", far}, {"from_lane_token", "a"}, {"to_lane_token", "b"}});
    });
  });
  const Issues found = d.validate();
  expect_only(found, "graph.lane_changes");
  EXPECT_EQ(found.count(Severity::kError), 2u) << found.format();
}

TEST(ValidateDataset, EdgeIndexOutOfRange) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    add_to_graph(f, [&](json& g) {
      g["edges"].push_back({{"source", 0}, {"target", g["nodes"].size() + 5}, {"lane_token", "x"}});
    });
  });
  expect_only(d.validate(), "graph.indices");
}

// The typed graph reader lists every reference problem of a graph in one pass: two edges
// and a lane change naming no node, a node id repeated.
TEST(ValidateDataset, EveryReferenceProblemOfAGraphIsListed) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    add_to_graph(f, [&](json& g) {
      ASSERT_GE(g["nodes"].size(), 2u);
      g["edges"].push_back({{"source", 0}, {"target", g["nodes"].size() + 5}, {"lane_token", "x"}});
      g["edges"].push_back({{"source", g["nodes"].size() + 9}, {"target", 1}, {"lane_token", "x"}});
      g["lane_changes"].push_back({{"source", 0}, {"target", 12345}, {"from_lane_token", "a"}, {"to_lane_token", "b"}});
      g["nodes"][1]["id"] = 0;
    });
  });
  const Issues found = d.validate();
  // Node 1's id is 0 (a repeat, and not its position); every edge naming node 1 now names
  // no node, so the count of graph.indices is at least the four planted.
  EXPECT_EQ(checks_of(found), (std::set<std::string>{"graph.indices", "graph.lane_changes"})) << found.format();
  EXPECT_GE(found.count_check("graph.indices"), 4u) << found.format();
  EXPECT_GE(found.count_check("graph.lane_changes"), 1u) << found.format();
}

// A map-update tile's prior graph is read as the graph is: an edge naming no node is listed
// under its JSON path in /prior, a well-formed prior passes.
TEST(ValidateDataset, AMapUpdateTilesPriorGraphIsCheckedToo) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    edit_json(f, "graph.json", [](json& g) {
      json prior = {{"nodes", g["nodes"]}, {"edges", g["edges"]}, {"lane_changes", json::array()}};
      for (json& e : prior["edges"]) e["change"] = "unchanged";
      prior["edges"].push_back({{"source", 0}, {"target", 99999}, {"lane_token", "gone"}, {"change", "removed"}});
      g["prior"] = prior;
    });
  });
  const Issues found = d.validate();
  expect_only(found, "graph.indices");
  EXPECT_EQ(found.size(), 1u) << found.format();
  EXPECT_NE(found.format().find("/prior/edges/"), std::string::npos) << found.format();
}

// A rule only the typed reader states (west < east) is reported once, under meta.schema,
// and the checks that need the tile's bounds wait for it.
TEST(ValidateDataset, MetaBoundsTheSchemaCannotOrder) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    edit_json(f, "meta.json", [](json& m) { std::swap(m["bounds_m"][0], m["bounds_m"][2]); });
  });
  const Issues found = d.validate();
  expect_only(found, "meta.schema");
  EXPECT_EQ(found.size(), 1u) << found.format();
  EXPECT_NE(found.format().find("meta.json:/bounds_m: x_west < x_east"), std::string::npos) << found.format();
}

TEST(ValidateDataset, PixelCoordinatesDisagreeWithMetres) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [&](TileFiles& f) {
    edit_json(f, "graph.json", [](json& g) { g["nodes"][0]["u"] = g["nodes"][0]["u"].get<double>() + 1.0; });
  });
  expect_only(d.validate(), "graph.pixel_coords");
}

TEST(ValidateDataset, TruncatedGraphJson) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) { f["graph.json"].resize(f["graph.json"].size() / 2); });
  expect_only(d.validate(), "graph.schema");
}

TEST(ValidateDataset, GraphWithWrongTypes) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "",
              [](TileFiles& f) { edit_json(f, "graph.json", [](json& g) { g["nodes"][0]["x"] = "east"; }); });
  expect_only(d.validate(), "graph.schema");
}

TEST(ValidateDataset, WrongVehicleDtype) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    reencode(f, "vehicle.tif", [](io::Raster& r, io::GeoRef&) {
      r.type = io::SampleType::kUInt8;
      r.data.assign(static_cast<size_t>(r.width) * r.height, 0);
    });
  });
  expect_only(d.validate(), "raster.dtype");
}

TEST(ValidateDataset, VehicleValueOne) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    reencode(f, "vehicle.tif", [](io::Raster& r, io::GeoRef&) {
      float v = 0;
      std::memcpy(&v, r.data.data(), 4);
      ASSERT_EQ(v, -1.0f);  // pixel 0 had no vehicle: the vehicle_px count stays right
      v = 1.0f;
      std::memcpy(r.data.data(), &v, 4);
    });
  });
  const Issues issues = d.validate();
  expect_only(issues, "raster.nodata");
  EXPECT_NE(issues.format().find("first: 1"), std::string::npos) << issues.format();
}

TEST(ValidateDataset, WrongRasterSize) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    reencode(f, "lidar.tif", [](io::Raster& r, io::GeoRef&) {
      r.width = r.height = 64;
      r.data.assign(64 * 64, 0);
    });
  });
  expect_only(d.validate(), "raster.size");
}

TEST(ValidateDataset, RasterGeorefShifted) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    reencode(f, "semantic.tif", [](io::Raster&, io::GeoRef& g) { g.y_north_m += 1.0; });
  });
  expect_only(d.validate(), "raster.georef");
}

TEST(ValidateDataset, CoverageFlagMissingWhereLidarHasData) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    const io::Raster lidar = io::decode_geotiff(f.at("lidar.tif"), "lidar");
    reencode(f, "coverage.tif", [&](io::Raster& r, io::GeoRef&) {
      for (size_t i = 0; i < r.data.size(); ++i)
        if (lidar.data[i] != 0) {
          r.data[i] &= static_cast<uint8_t>(~1u);
          break;
        }
    });
  });
  const std::set<std::string> checks = checks_of(d.validate());
  EXPECT_TRUE(checks.count("raster.nodata"));
  EXPECT_TRUE(checks.count("meta.counts"));  // the lidar coverage fraction no longer matches
}

TEST(ValidateDataset, MetaCountOffByOne) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "", [](TileFiles& f) {
    edit_json(f, "meta.json", [](json& m) { m["counts"]["nodes"] = m["counts"]["nodes"].get<int>() + 1; });
  });
  expect_only(d.validate(), "meta.counts");
}

TEST(ValidateDataset, ManifestCountOffByOne) {
  DatasetCopy d;
  json m = d.manifest();
  m["counts"]["test"]["tiles"] = m["counts"]["test"]["tiles"].get<int>() + 1;
  d.write_manifest(m);
  const Issues issues = d.validate();
  expect_only(issues, "split.counts");
  EXPECT_NE(issues.format().find("/counts/test/tiles"), std::string::npos) << issues.format();
}

TEST(ValidateDataset, MissingShard) {
  DatasetCopy d;
  fs::remove(d.root() / d.shard("test", 1)["file"].get<std::string>());
  const std::set<std::string> checks = checks_of(d.validate());
  EXPECT_TRUE(checks.count("shard.present"));
  EXPECT_TRUE(checks.count("split.counts"));  // its tiles are not found
  EXPECT_EQ(checks.size(), 2u);
}

TEST(ValidateDataset, TruncatedShard) {
  DatasetCopy d;
  const json shard = d.shard("test");
  const fs::path path = d.root() / shard["file"].get<std::string>();
  std::string bytes = read_file(path);
  bytes.resize(bytes.size() / 2);
  write_text(path, bytes);
  json m = d.manifest();
  for (json& s : m["shards"])
    if (s["name"] == shard["name"]) {
      s["sha256"] = sha256_hex(bytes);
      s["bytes"] = bytes.size();
    }
  d.write_manifest(m);
  EXPECT_TRUE(checks_of(d.validate()).count("shard.readable"));
}

TEST(ValidateDataset, ManifestMissingField) {
  DatasetCopy d;
  json m = d.manifest();
  m.erase("tool");
  d.write_manifest(m);
  expect_only(d.validate(), "manifest.schema");
}

TEST(ValidateDataset, ConfigSeedDiffersFromManifestSeed) {
  DatasetCopy d;
  json m = d.manifest();
  m["seed"] = m["seed"].get<int>() + 1;
  d.write_manifest(m);
  expect_only(d.validate(), "determinism.config");
}

TEST(ValidateDataset, ConfigWithUnknownKey) {
  DatasetCopy d;
  json m = d.manifest();
  m["config"]["graph"]["max_spacing"] = 2.0;
  d.write_manifest(m);
  expect_only(d.validate(), "determinism.config");
}

TEST(ValidateDataset, MetaOfAnotherSplit) {
  DatasetCopy d;
  d.edit_tile(d.shard("test")["name"], "",
              [](TileFiles& f) { edit_json(f, "meta.json", [](json& m) { m["split"] = "train"; }); });
  EXPECT_TRUE(checks_of(d.validate()).count("meta.schema"));
}

TEST(ValidateDataset, FolderLayoutCleanThenMissingFile) {
  TempDir tmp("validate-folder");
  std::vector<std::string> args = e2e_generate_args(tmp / "ds");
  args.insert(args.end(), {"--layout", "folder", "--threads", "2"});
  const CommandResult r = run_nsgraph(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  validate::DatasetValidateOptions o;
  o.root = tmp / "ds";
  Issues issues = validate::validate_dataset(o);
  EXPECT_TRUE(issues.empty()) << issues.format();
  const json m = json::parse(read_file(o.root / "manifest.json"));
  const std::string key = m["shards"][0]["first_key"];
  fs::remove(o.root / m["shards"][0]["folder"].get<std::string>() / key / (key + ".rgb.tif"));
  issues = validate::validate_dataset(o);
  expect_only(issues, "shard.members");
}

TEST(ValidateSchemas, ConfigFilesAndGeneratedDocumentsValidate) {
  const fs::path v1 = source_dir() / "schemas" / "v1";
  const validate::SchemaValidator config(v1 / "generate-config.schema.json");
  for (const char* file : {"samples/generate.json", "tests/data/generate/e2e.json"}) {
    const Issues issues = config.validate(json::parse(read_file(source_dir() / file)), file, "config");
    EXPECT_TRUE(issues.empty()) << issues.format();
  }
  const Issues bad = config.validate(json{{"crops", {{"size_px", 4}}}, {"sed", 1}}, "bad", "config");
  EXPECT_EQ(bad.size(), 2u) << bad.format();
  // Every v1 schema is draft-07 with a versioned $id, and requires schema_version "1".
  for (const auto& e : fs::directory_iterator(v1)) {
    const json s = json::parse(read_file(e.path()));
    EXPECT_EQ(s["$schema"], "http://json-schema.org/draft-07/schema#") << e.path();
    EXPECT_NE(s["$id"].get<std::string>().find("/v1/" + e.path().filename().string()), std::string::npos);
    EXPECT_EQ(s["properties"]["schema_version"]["const"], "1") << e.path();
  }
}

// --- the command line ---------------------------------------------------------------

TEST(ValidateCli, CleanDatasetExitsZero) {
  const CommandResult r = run_nsgraph({"validate", e2e_dataset().string()});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("0 error(s), 0 warning(s)"), std::string::npos) << r.out;
}

TEST(ValidateCli, ProblemsExitOneWithOneLinePerProblem) {
  DatasetCopy d;
  json m = d.manifest();
  m["counts"]["total_tiles"] = 1;
  m["seed"] = 99;
  d.write_manifest(m);
  const CommandResult r = run_nsgraph({"validate", d.root().string()});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("error split.counts manifest.json:/counts/total_tiles: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("error determinism.config "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 error(s)"), std::string::npos) << r.out;

  const CommandResult j = run_nsgraph({"validate", d.root().string(), "--json"});
  EXPECT_EQ(j.exit_code, 1);
  const json doc = json::parse(j.out);
  EXPECT_EQ(doc["summary"]["errors"], 2);
  EXPECT_EQ(doc["issues"][0]["check"], "determinism.config");
  EXPECT_EQ(doc["issues"][0]["severity"], "error");

  // Selecting other checks hides both problems.
  const CommandResult g = run_nsgraph({"validate", d.root().string(), "--checks", "graph.*,raster.*"});
  EXPECT_EQ(g.exit_code, 0) << g.out;
}

TEST(ValidateCli, ListChecksAndBadPattern) {
  const CommandResult r = run_nsgraph({"validate", "--list-checks"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("graph.edge_length\t"), std::string::npos);
  EXPECT_EQ(static_cast<size_t>(std::count(r.out.begin(), r.out.end(), '\n')), validate::dataset_checks().size());
  const CommandResult g = run_nsgraph({"validate", "--list-checks", "--checks", "split.*"});
  EXPECT_EQ(std::count(g.out.begin(), g.out.end(), '\n'), 2);
  const CommandResult bad = run_nsgraph({"validate", e2e_dataset().string(), "--checks", "nothing.*"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--checks"), std::string::npos) << bad.err;
}

TEST(ValidateCli, UnreadableManifestExitsTwo) {
  DatasetCopy d;
  const std::string text = read_file(d.root() / "manifest.json");
  write_text(d.root() / "manifest.json", text.substr(0, text.size() / 3));
  const CommandResult r = run_nsgraph({"validate", d.root().string()});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
  const CommandResult missing = run_nsgraph({"validate", (d.root() / "nowhere").string()});
  EXPECT_EQ(missing.exit_code, 2);
}

}  // namespace
}  // namespace nsg::test
