// The manifest's one reader and writer (io/manifest.h) on crafted documents: every field the
// model holds is read, every limit of the format refuses by file and JSON pointer, and the
// writer gives back the bytes it read.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "nsg/core/error.h"
#include "nsg/io/dataset.h"
#include "nsg/io/manifest.h"
#include "nsg/io/tile_meta.h"
#include "test_support.h"

namespace nsg::io {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

const std::string kFile = "ds/manifest.json";
const std::string kHash = std::string(64, 'a');

// A complete tar-layout manifest of one location, one test shard and a ladder rung, fields
// in the order merge writes them.
ordered_json valid_manifest() {
  const std::string key = "boston-seaport-test-000000";
  return ordered_json::parse(R"({
    "schema_version": "1",
    "tool": {"name": "nsgraph", "version": "0.0.0"},
    "licence": {"name": "CC BY-NC-SA 4.0", "url": "u", "source": "nuScenes"},
    "seed": 7,
    "config": {"seed": 7, "splits": {"buffer_m": 51.2}},
    "inputs": {"dataroot": "/data/nuscenes", "version": "v1.0-mini",
               "tables": [{"file": "v1.0-mini/scene.json", "sha256": ")" +
                             kHash + R"(", "bytes": 10}],
               "map_expansion": {"boston-seaport": {"file": "maps/expansion/boston-seaport.json",
                                                    "sha256": ")" +
                             kHash + R"(", "bytes": 5, "version": "1.3"}},
               "detections": null},
    "georeference": {"frame": "f", "projection": "p", "note": "n", "locations": {}},
    "layout": "tar",
    "tile_format": {"resolution_m": 0.2, "size_px": 256, "key_pattern": "<location>-<split>-<NNNNNN>",
                    "files": ["lidar.tif", "graph.json", "meta.json"]},
    "locations": [{"name": "boston-seaport", "map_version": "1.3",
                   "lane_graph": {"nodes": 10, "edges": 9, "lanes": 2, "map_defects": 0},
                   "scenes": {"used": 2, "excluded": [{"name": "scene-0499", "reason": "off the map"}]},
                   "regions": [{"name": "r0", "split": "test", "bounds_m": [0.0, 0.0, 100.5, 100.25]}],
                   "counts": {"train": 0, "val": 0, "test": 1},
                   "shards": [{"name": "test-000000", "split": "test", "tiles": 1,
                               "first_key": ")" +
                             key + R"(", "last_key": ")" + key + R"("}],
                   "rung_shards": [{"name": "test-r1-000000", "split": "test", "rung": 1, "tiles": 1,
                                    "first_key": ")" +
                             key + R"(-r1", "last_key": ")" + key + R"(-r1"}]}],
    "excluded_scenes": [{"name": "scene-0499", "location": "boston-seaport", "reason": "off the map"}],
    "counts": {"train": {"tiles": 0, "shards": 0}, "val": {"tiles": 0, "shards": 0},
               "test": {"tiles": 1, "shards": 1}, "total_tiles": 1},
    "shards": [{"name": "test-000000", "split": "test", "location": "boston-seaport", "tiles": 1,
                "first_key": ")" +
                             key + R"(", "last_key": ")" + key + R"(",
                "file": "shards/test-000000.tar", "sha256": ")" +
                             kHash + R"(", "bytes": 2048}],
    "maps": [{"file": "maps/boston-seaport/lanes.geojson", "sha256": ")" +
                             kHash + R"(", "bytes": 3}],
    "ladder": {"rungs": [1, "all"], "order": "time", "splits": ["test"],
               "counts": {"1": {"tiles": 1, "shards": 1}},
               "shards": [{"name": "test-r1-000000", "split": "test", "location": "boston-seaport", "tiles": 1,
                           "first_key": ")" +
                             key + R"(-r1", "last_key": ")" + key + R"(-r1",
                           "file": "shards/test-r1-000000.tar", "sha256": ")" +
                             kHash + R"(", "bytes": 1024,
                           "rung": 1}]}
  })");
}

// The ParseError the reader throws for `doc` (a failure when it throws none).
ParseError refusal(const ordered_json& doc) {
  try {
    manifest_from_json(doc, kFile);
  } catch (const ParseError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted: " << doc.dump();
  return ParseError("", "", "");
}

TEST(Manifest, ReadsEveryFieldOfTheModel) {
  const Manifest m = manifest_from_json(valid_manifest(), kFile);
  EXPECT_EQ(m.seed, 7u);
  EXPECT_TRUE(m.tar_layout());
  EXPECT_EQ(m.tile_format.size_px, 256);
  EXPECT_DOUBLE_EQ(m.tile_format.resolution_m, 0.2);
  EXPECT_EQ(m.tile_format.files.size(), 3u);
  ASSERT_EQ(m.shards.size(), 1u);
  const ShardEntry& s = m.shards[0];
  EXPECT_EQ(s.name, "test-000000");
  EXPECT_EQ(s.split, "test");
  EXPECT_EQ(s.location, "boston-seaport");
  EXPECT_EQ(s.tiles, 1);
  EXPECT_EQ(s.file, "shards/test-000000.tar");
  EXPECT_EQ(s.path(), s.file);
  EXPECT_EQ(s.bytes, 2048);
  EXPECT_EQ(s.rung, 0);
  EXPECT_EQ(m.counts.test.tiles, 1);
  EXPECT_EQ(m.counts.of("test"), &m.counts.test);
  EXPECT_EQ(m.counts.of("dev"), nullptr);
  EXPECT_EQ(m.counts.total_tiles, 1);
  ASSERT_EQ(m.locations.size(), 1u);
  ASSERT_EQ(m.locations[0].regions.size(), 1u);
  EXPECT_EQ(m.locations[0].regions[0].bounds_m[2], 100.5);
  EXPECT_EQ(m.locations[0].counts.test, 1);
  EXPECT_EQ(m.location("boston-seaport"), &m.locations[0]);
  ASSERT_NE(m.inputs.map_of("boston-seaport"), nullptr);
  EXPECT_EQ(m.inputs.map_of("boston-seaport")->version, "1.3");
  EXPECT_FALSE(m.inputs.detections);
  ASSERT_EQ(m.maps.size(), 1u);
  ASSERT_TRUE(m.ladder);
  EXPECT_EQ(m.ladder->rungs, (std::vector<int>{1, kRungAll}));
  ASSERT_EQ(m.ladder->shards.size(), 1u);
  EXPECT_EQ(m.ladder->shards[0].rung, 1);
  EXPECT_EQ(m.config["seed"], 7);
}

TEST(Manifest, TheWriterGivesBackTheBytesItRead) {
  const ordered_json doc = valid_manifest();
  const std::string text = doc.dump(1) + "\n";
  EXPECT_EQ(manifest_text(manifest_from_text(text, kFile)), text);
  // Without the optional parts too (an older v1 manifest), and in the folder layout.
  ordered_json older = doc;
  for (const char* part : {"tool", "licence", "georeference", "excluded_scenes", "ladder"}) older.erase(part);
  older["locations"][0].erase("scenes");
  older["locations"][0].erase("rung_shards");
  older["layout"] = "folder";
  older["shards"][0].erase("file");
  older["shards"][0].erase("sha256");
  older["shards"][0].erase("bytes");
  older["shards"][0]["folder"] = "tiles/test";
  older["shards"][0]["sha256"] = kHash;
  older["shards"][0]["bytes"] = 1;
  const std::string older_text = older.dump(1) + "\n";
  EXPECT_EQ(manifest_text(manifest_from_text(older_text, kFile)), older_text);
}

// One refusal per field and limit: the pointer, and words of what was expected.
struct Case {
  std::string pointer;
  std::function<void(ordered_json&)> edit;
  std::string expected;  // a part of the message
};

TEST(Manifest, EveryMissingMistypedOrOutOfRangeFieldIsNamedByItsPointer) {
  const std::vector<Case> cases = {
      {"/shards/0/bytes", [](ordered_json& m) { m["shards"][0]["bytes"] = "2048"; }, "an integer"},
      {"/shards/0/bytes", [](ordered_json& m) { m["shards"][0]["bytes"] = -1; }, "an integer in [0, "},
      {"/shards/0/bytes", [](ordered_json& m) { m["shards"][0]["bytes"] = 1.5; }, "an integer"},
      {"/shards/0/sha256", [](ordered_json& m) { m["shards"][0]["sha256"] = 12; }, "a string"},
      {"/shards/0/sha256", [](ordered_json& m) { m["shards"][0]["sha256"] = std::string(64, 'A'); }, "lowercase hex"},
      {"/shards/0/sha256", [](ordered_json& m) { m["shards"][0]["sha256"] = "abc"; }, "64 lowercase hex"},
      {"/shards/0/tiles", [](ordered_json& m) { m["shards"][0]["tiles"] = -3; }, "an integer in [0, "},
      {"/shards/0/tiles", [](ordered_json& m) { m["shards"][0]["tiles"] = kMaxManifestTiles + 1; }, "an integer in"},
      {"/shards/0/tiles", [](ordered_json& m) { m["shards"][0].erase("tiles"); }, "a field 'tiles'"},
      {"/shards/0/file", [](ordered_json& m) { m["shards"][0]["file"] = "../x"; }, "inside the dataset"},
      {"/shards/0/file", [](ordered_json& m) { m["shards"][0]["file"] = "/etc/passwd"; }, "inside the dataset"},
      {"/shards/0/file", [](ordered_json& m) { m["shards"][0]["file"] = ""; }, "inside the dataset"},
      {"/shards/0/file", [](ordered_json& m) { m["shards"][0].erase("file"); }, "a field 'file'"},
      {"/shards/0/folder", [](ordered_json& m) { m["layout"] = "folder"; }, "a field 'folder'"},
      {"/shards/0/split", [](ordered_json& m) { m["shards"][0]["split"] = "dev"; }, "train, val or test"},
      {"/shards/0/name", [](ordered_json& m) { m["shards"][0]["name"] = "../../x"; }, "a shard name test-NNNNNN"},
      {"/shards/0/name", [](ordered_json& m) { m["shards"][0]["name"] = "train-000000"; }, "test-NNNNNN"},
      {"/shards/0/location", [](ordered_json& m) { m["shards"][0]["location"] = "a/b"; }, "letters, digits"},
      {"/shards", [](ordered_json& m) { m["shards"] = ordered_json::object(); }, "an array"},
      {"/shards/0", [](ordered_json& m) { m["shards"][0] = 5; }, "a shard entry"},
      {"/tile_format", [](ordered_json& m) { m.erase("tile_format"); }, "a field 'tile_format'"},
      {"/tile_format/size_px", [](ordered_json& m) { m["tile_format"]["size_px"] = 9000; }, "[1, 4096]"},
      {"/tile_format/size_px", [](ordered_json& m) { m["tile_format"]["size_px"] = 0; }, "[1, 4096]"},
      {"/tile_format/size_px", [](ordered_json& m) { m["tile_format"]["size_px"] = "256"; }, "an integer"},
      {"/tile_format/resolution_m", [](ordered_json& m) { m["tile_format"]["resolution_m"] = 0; }, "(0, 100]"},
      {"/tile_format/resolution_m", [](ordered_json& m) { m["tile_format"]["resolution_m"] = -0.2; }, "(0, 100]"},
      {"/tile_format/files/1", [](ordered_json& m) { m["tile_format"]["files"][1] = 3; }, "a non-empty string"},
      {"/layout", [](ordered_json& m) { m["layout"] = "zip"; }, "tar or folder"},
      {"/schema_version", [](ordered_json& m) { m["schema_version"] = "2"; }, "schema v1"},
      {"/seed", [](ordered_json& m) { m["seed"] = -7; }, "an unsigned integer"},
      {"/config", [](ordered_json& m) { m["config"] = "x"; }, "config"},
      {"/counts/test/tiles", [](ordered_json& m) { m["counts"]["test"]["tiles"] = "1"; }, "an integer"},
      {"/counts/total_tiles", [](ordered_json& m) { m["counts"].erase("total_tiles"); }, "a field 'total_tiles'"},
      {"/maps/0/file", [](ordered_json& m) { m["maps"][0]["file"] = "../../etc/hostname"; }, "inside the dataset"},
      {"/maps/0/bytes", [](ordered_json& m) { m["maps"][0]["bytes"] = nullptr; }, "an integer"},
      {"/inputs/tables/0/sha256", [](ordered_json& m) { m["inputs"]["tables"][0]["sha256"] = 1; }, "a string"},
      {"/inputs/map_expansion/a~1b/version",
       [](ordered_json& m) {
         m["inputs"]["map_expansion"]["a/b"] = {{"file", "f"}, {"sha256", kHash}, {"bytes", 1}};
       },
       "a field 'version'"},
      {"/inputs/detections/bytes",
       [](ordered_json& m) {
         m["inputs"]["detections"] = {{"file", "d.json"}, {"sha256", kHash}};
       },
       "a field 'bytes'"},
      {"/locations/0/name", [](ordered_json& m) { m["locations"][0]["name"] = ".."; }, "letters, digits"},
      {"/locations/0/regions/0/split", [](ordered_json& m) { m["locations"][0]["regions"][0]["split"] = "x"; },
       "train, val or test"},
      {"/locations/0/regions/0/bounds_m",
       [](ordered_json& m) {
         m["locations"][0]["regions"][0]["bounds_m"] = {1, 2};
       },
       "x_west"},
      {"/locations/0/counts/val", [](ordered_json& m) { m["locations"][0]["counts"]["val"] = -1; }, "an integer"},
      {"/locations/0/shards/0/tiles", [](ordered_json& m) { m["locations"][0]["shards"][0]["tiles"] = true; },
       "an integer"},
      {"/locations/0/rung_shards/0/rung", [](ordered_json& m) { m["locations"][0]["rung_shards"][0]["rung"] = 0; },
       "[1, 100000]"},
      {"/ladder/shards/0/rung", [](ordered_json& m) { m["ladder"]["shards"][0]["rung"] = 100001; }, "[1, 100000]"},
      {"/ladder/shards/0/rung", [](ordered_json& m) { m["ladder"]["shards"][0].erase("rung"); }, "a field 'rung'"},
      {"/ladder/shards/0/name", [](ordered_json& m) { m["ladder"]["shards"][0]["rung"] = 2; }, "test-r2-NNNNNN"},
      {"/ladder/rungs/1", [](ordered_json& m) { m["ladder"]["rungs"][1] = "most"; }, "an integer in [1, 100000]"},
      {"/ladder/order", [](ordered_json& m) { m["ladder"]["order"] = "random"; }, "time or seeded"},
      {"/ladder/splits/0", [](ordered_json& m) { m["ladder"]["splits"][0] = "dev"; }, "train, val or test"},
      {"/ladder/counts/01", [](ordered_json& m) { m["ladder"]["counts"]["01"] = m["ladder"]["counts"]["1"]; },
       "a rung"},
  };
  for (const Case& c : cases) {
    ordered_json doc = valid_manifest();
    c.edit(doc);
    const ParseError e = refusal(doc);
    EXPECT_EQ(e.file(), kFile) << c.pointer;
    EXPECT_EQ(e.record(), c.pointer) << e.what();
    EXPECT_NE(e.expected().find(c.expected), std::string::npos) << c.pointer << ": " << e.what();
  }
}

TEST(Manifest, TheSizeBoundIsTheTileMetasOne) {
  // One bound for a tile's side, in the manifest and in a tile's meta.json.
  ordered_json doc = valid_manifest();
  doc["tile_format"]["size_px"] = kMaxTileSizePx;
  EXPECT_EQ(manifest_from_json(doc, kFile).tile_format.size_px, 4096);
  doc["tile_format"]["size_px"] = kMaxTileSizePx + 1;
  EXPECT_EQ(refusal(doc).record(), "/tile_format/size_px");
}

TEST(Manifest, ListsLongerThanTheLimitAreRefusedBeforeTheirEntriesAreRead) {
  ordered_json doc = valid_manifest();
  doc["shards"] = ordered_json::array();
  for (int64_t i = 0; i <= kMaxManifestEntries; ++i) doc["shards"].push_back(nullptr);
  const ParseError e = refusal(doc);
  EXPECT_EQ(e.record(), "/shards");
  EXPECT_NE(e.expected().find("at most 200000 entries"), std::string::npos) << e.what();
}

TEST(Manifest, NestingBeyondTheLimitIsRefused) {
  ordered_json doc = valid_manifest();
  ordered_json deep = 1;
  for (int i = 0; i < kMaxManifestDepth; ++i) deep = ordered_json::array({deep});
  doc["config"]["deep"] = deep;
  try {
    manifest_from_text(doc.dump(), kFile);
    ADD_FAILURE() << "accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), kFile);
    EXPECT_NE(std::string(e.what()).find("nest"), std::string::npos) << e.what();
  }
  // A repeated key is refused too (the strict parse).
  EXPECT_THROW(manifest_from_text(R"({"seed": 1, "seed": 2})", kFile), ParseError);
  EXPECT_THROW(manifest_from_text("[1, 2", kFile), ParseError);
}

TEST(Manifest, AFileBeyondTheSizeBoundIsRefusedBeforeItIsRead) {
  nsg::test::TempDir dir("manifest-size");
  const fs::path path = dir / "manifest.json";
  std::ofstream(path) << "{}";
  fs::resize_file(path, static_cast<uintmax_t>(kMaxManifestBytes) + 1);  // sparse: nothing is written
  try {
    read_manifest(path);
    ADD_FAILURE() << "accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_NE(e.expected().find("at most 128 MiB"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_manifest(dir / "none.json"), IoError);
}

TEST(Manifest, DatasetOpenReadsThroughTheReader) {
  nsg::test::TempDir dir("manifest-dataset");
  ordered_json doc = valid_manifest();
  nsg::test::write_text(dir / "manifest.json", doc.dump(1));
  const Dataset ds = Dataset::open(dir.path());
  EXPECT_EQ(ds.shards("test").size(), 1u);
  EXPECT_EQ(ds.shards("test-r1").size(), 1u);
  EXPECT_EQ(ds.rungs(), std::vector<int>{1});
  EXPECT_EQ(ds.tile_count("test"), 1u);
  EXPECT_EQ(ds.split_names(), (std::vector<std::string>{"test", "test-r1"}));
  doc["shards"][0]["bytes"] = "many";
  nsg::test::write_text(dir / "manifest.json", doc.dump(1));
  try {
    Dataset::open(dir.path());
    ADD_FAILURE() << "accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), (dir / "manifest.json").string());
    EXPECT_EQ(e.record(), "/shards/0/bytes");
  }
}

// No manifest: the error says what the folder is instead (a nuScenes release, an unfinished
// generate run) and what to do; a manifest that is a device (a link to /dev/zero) is refused
// without reading it.
TEST(Manifest, AMissingOrSpecialManifestIsExplained) {
  nsg::test::TempDir dir("manifest-missing");
  fs::create_directories(dir / "release" / "v1.0-mini");
  fs::create_directories(dir / "unfinished" / "parts");
  fs::create_directories(dir / "empty");
  const auto message = [](const fs::path& path) -> std::string {
    try {
      read_manifest(path);
    } catch (const IoError& e) {
      return e.what();
    }
    return "no IoError";
  };
  EXPECT_NE(message(dir / "release" / "manifest.json").find("nuScenes release"), std::string::npos);
  EXPECT_NE(message(dir / "release" / "manifest.json").find("nsgraph generate --dataroot"), std::string::npos);
  EXPECT_NE(message(dir / "unfinished" / "manifest.json").find("unfinished generate run"), std::string::npos);
  EXPECT_NE(message(dir / "empty" / "manifest.json").find("nsgraph generate"), std::string::npos);
  fs::create_symlink("/dev/zero", dir / "empty" / "manifest.json");
  try {
    read_manifest(dir / "empty" / "manifest.json");
    ADD_FAILURE() << "read a device";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("a regular file"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nsg::io
