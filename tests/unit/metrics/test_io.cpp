// Ground-truth readers: submission-format files, dataset folders and WebDataset tars.
#include <archive.h>
#include <archive_entry.h>
#include <gtest/gtest.h>

#include <functional>

#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/io/tile_members.h"
#include "nsg/metrics/io.h"
#include "manifest_fixture.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

namespace fs = std::filesystem;

std::string graph_doc(const std::string& key, double shift) {
  nlohmann::json doc = {
      {"schema_version", "1"}, {"key", key}, {"nodes", nlohmann::json::array()}, {"edges", nlohmann::json::array()}};
  // Ids deliberately not equal to indices.
  for (int k = 0; k < 3; ++k)
    doc["nodes"].push_back({{"id", 100 - k}, {"u", 10.0 * k + shift}, {"v", 5.0}, {"x", 0.0}, {"y", 0.0}});
  doc["edges"].push_back({{"source", 100}, {"target", 99}, {"lane_token", "a"}});
  doc["edges"].push_back({{"source", 98}, {"target", 99}, {"lane_token", "b"}});
  return doc.dump();
}

void write_tar(const fs::path& tar, const std::vector<std::pair<std::string, std::string>>& members) {
  archive* a = archive_write_new();
  archive_write_set_format_pax_restricted(a);
  ASSERT_EQ(archive_write_open_filename(a, tar.c_str()), ARCHIVE_OK);
  for (const auto& [name, data] : members) {
    archive_entry* e = archive_entry_new();
    archive_entry_set_pathname(e, name.c_str());
    archive_entry_set_size(e, static_cast<la_int64_t>(data.size()));
    archive_entry_set_filetype(e, AE_IFREG);
    archive_entry_set_perm(e, 0644);
    archive_write_header(a, e);
    archive_write_data(a, data.data(), data.size());
    archive_entry_free(e);
  }
  archive_write_close(a);
  archive_write_free(a);
}

void expect_tile(const Graph& g, double shift) {
  ASSERT_EQ(g.nodes.size(), 3u);
  EXPECT_DOUBLE_EQ(g.nodes[1].u, 10.0 + shift);
  ASSERT_EQ(g.edges.size(), 2u);
  EXPECT_EQ(g.edges[0], (std::array<int64_t, 2>{0, 1}));  // ids 100 -> 99
  EXPECT_EQ(g.edges[1], (std::array<int64_t, 2>{2, 1}));  // ids 98 -> 99
}

// A manifest shard entry as `generate` writes it (docs/dataset-format.md).
nlohmann::json tar_shard(const fs::path& root, const std::string& name, const std::string& split,
                         const std::string& first, const std::string& last, int tiles) {
  const fs::path file = root / "shards" / (name + ".tar");
  return {{"name", name},
          {"split", split},
          {"location", "boston"},
          {"tiles", tiles},
          {"first_key", first},
          {"last_key", last},
          {"file", "shards/" + name + ".tar"},
          {"sha256", sha256_file(file)},
          {"bytes", fs::file_size(file)}};
}

void write_manifest(const fs::path& root, const nlohmann::json& shards, const std::string& layout) {
  nsg::test::write_text(root / "manifest.json", nsg::test::complete_manifest(shards, layout).dump());
}

// Two test shards and a train shard, all listed.
void write_tar_dataset(const fs::path& root) {
  fs::create_directories(root / "shards");
  write_tar(root / "shards" / "test-000000.tar", {{"k0.graph.json", graph_doc("k0", 0.0)}, {"k0.meta.json", "{}"}});
  write_tar(root / "shards" / "test-000001.tar", {{"k1.graph.json", graph_doc("k1", 1.0)}});
  write_tar(root / "shards" / "train-000000.tar", {{"t.graph.json", graph_doc("t", 7.0)}});
  write_manifest(
      root,
      {tar_shard(root, "test-000000", "test", "k0", "k0", 1), tar_shard(root, "test-000001", "test", "k1", "k1", 1),
       tar_shard(root, "train-000000", "train", "t", "t", 1)},
      "tar");
}

template <class E>
E expect_refused(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const E& e) {
    return e;
  }
  ADD_FAILURE() << "no error";
  return E("", "", "");
}

TEST(Io, WebDatasetShardsThroughTheManifest) {
  nsg::test::TempDir dir("metrics-tar");
  write_tar_dataset(dir.path());
  const GraphSet set = load_dataset_split(dir.path(), "test");
  ASSERT_EQ(set.size(), 2u);
  expect_tile(set.at("k0"), 0.0);
  expect_tile(set.at("k1"), 1.0);
  EXPECT_EQ(load_ground_truth(dir.path(), "train").size(), 1u);
}

TEST(Io, UnknownSplitIsNamedWithTheListedOnes) {
  nsg::test::TempDir dir("metrics-split");
  write_tar_dataset(dir.path());
  const auto e = expect_refused<DataError>([&] { load_ground_truth(dir.path(), "val"); });
  EXPECT_EQ(e.record(), "split 'val'");
  EXPECT_NE(e.expected().find("(test, train)"), std::string::npos) << e.what();
}

TEST(Io, LeftoverShardIsRefusedByName) {
  // A shard of an earlier run with more tiles, still beside the listed ones.
  nsg::test::TempDir dir("metrics-leftover");
  write_tar_dataset(dir.path());
  write_tar(dir / "shards" / "test-000002.tar", {{"k2.graph.json", graph_doc("k2", 2.0)}});
  const auto e = expect_refused<DataError>([&] { load_dataset_split(dir.path(), "test"); });
  EXPECT_EQ(e.file(), (dir / "shards" / "test-000002.tar").string());
  // Hashing off does not make it acceptable; another split does not see it.
  EXPECT_THROW(load_dataset_split(dir.path(), "test", false), DataError);
  EXPECT_EQ(load_dataset_split(dir.path(), "train").size(), 1u);
}

TEST(Io, ChangedShardIsRefusedUnlessHashingIsOff) {
  // The train shard copied into the test shard's name: same size, other bytes.
  nsg::test::TempDir dir("metrics-changed");
  write_tar_dataset(dir.path());
  std::string bytes = nsg::test::read_text(dir / "shards" / "test-000001.tar");
  const size_t at = bytes.find("\"u\":11.0");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 5] = '2';  // u 11 → 12, same length
  nsg::test::write_text(dir / "shards" / "test-000001.tar", bytes);
  const auto e = expect_refused<DataError>([&] { load_dataset_split(dir.path(), "test"); });
  EXPECT_EQ(e.file(), (dir / "shards" / "test-000001.tar").string());
  EXPECT_NE(e.expected().find("sha256"), std::string::npos);
  EXPECT_EQ(load_dataset_split(dir.path(), "test", false).size(), 2u);  // --no-verify: sizes only
  // A size change is caught without hashing.
  nsg::test::write_text(dir / "shards" / "test-000001.tar", bytes + std::string(512, '\0'));
  EXPECT_THROW(load_dataset_split(dir.path(), "test", false), DataError);
}

TEST(Io, MissingShardIsRefusedByName) {
  nsg::test::TempDir dir("metrics-missing");
  write_tar_dataset(dir.path());
  fs::remove(dir / "shards" / "test-000000.tar");
  const auto e = expect_refused<IoError>([&] { load_dataset_split(dir.path(), "test"); });
  EXPECT_EQ(e.file(), (dir / "shards" / "test-000000.tar").string());
  EXPECT_EQ(e.record(), "test-000000");
}

TEST(Io, NoManifestNoGroundTruth) {
  // Shards without a manifest were read by name pattern before; now the manifest is the list.
  nsg::test::TempDir dir("metrics-nomanifest");
  fs::create_directories(dir / "shards");
  write_tar(dir / "shards" / "test-000000.tar", {{"k0.graph.json", graph_doc("k0", 0.0)}});
  EXPECT_THROW(load_dataset_split(dir.path(), "test"), IoError);
}

// Folder layout: every member of a tile (dummy rasters: only graph.json is parsed), and
// the shard's digest as `generate` computes it.
TEST(Io, FolderLayoutThroughTheManifest) {
  nsg::test::TempDir dir("metrics-folder");
  std::string lines;
  int64_t bytes = 0;
  for (const std::string key : {"boston-test-000000", "boston-test-000001"})
    for (const io::TileMember& m : io::tile_members()) {
      const std::string rel = "tiles/test/" + key + "/" + key + "." + m.file;
      const std::string text = m.name == "graph" ? graph_doc(key, key.back() == '1' ? 1.0 : 0.0) : "x" + m.file;
      nsg::test::write_text(dir / rel, text);
      lines += rel + '\0' + sha256_hex(text) + "\n";
      bytes += static_cast<int64_t>(text.size());
    }
  const nlohmann::json shard = {{"name", "test-000000"},
                                {"split", "test"},
                                {"location", "boston"},
                                {"tiles", 2},
                                {"first_key", "boston-test-000000"},
                                {"last_key", "boston-test-000001"},
                                {"folder", "tiles/test"},
                                {"sha256", sha256_hex(lines)},
                                {"bytes", bytes}};
  write_manifest(dir.path(), nlohmann::json::array({shard}), "folder");
  const GraphSet set = load_ground_truth(dir.path(), "test");
  ASSERT_EQ(set.size(), 2u);
  expect_tile(set.at("boston-test-000000"), 0.0);
  expect_tile(set.at("boston-test-000001"), 1.0);

  // A tile folder the manifest does not list.
  nsg::test::write_text(dir / "tiles/test/boston-test-000007/boston-test-000007.graph.json",
                        graph_doc("boston-test-000007", 0.0));
  const auto e = expect_refused<DataError>([&] { load_ground_truth(dir.path(), "test"); });
  EXPECT_EQ(e.file(), (dir / "tiles/test/boston-test-000007").string());
  fs::remove_all(dir / "tiles/test/boston-test-000007");

  // A member changed in place, its size kept: only the digest tells (so skipping the
  // sha256 check makes this test fail), and --no-verify accepts it.
  std::string raster_file;  // a dummy raster: never parsed
  for (const io::TileMember& m : io::tile_members())
    if (m.name != "graph" && m.name != "meta" && raster_file.empty()) raster_file = m.file;
  const fs::path member = dir / "tiles/test/boston-test-000000" / ("boston-test-000000." + raster_file);
  std::string member_bytes = nsg::test::read_text(member);
  member_bytes[0] = member_bytes[0] == 'y' ? 'z' : 'y';
  nsg::test::write_text(member, member_bytes);
  const auto changed = expect_refused<DataError>([&] { load_ground_truth(dir.path(), "test"); });
  EXPECT_NE(changed.expected().find("digest"), std::string::npos) << changed.what();
  EXPECT_EQ(load_dataset_split(dir.path(), "test", false).size(), 2u);

  // A tile removed: the digest (and without hashing, the manifest's count) tells.
  fs::remove_all(dir / "tiles/test/boston-test-000001");
  EXPECT_THROW(load_ground_truth(dir.path(), "test"), DataError);
  EXPECT_THROW(load_dataset_split(dir.path(), "test", false), DataError);
}

// The ground truth's graph comes through the dataset's one graph reader (io::DatasetTile::graph).
TEST(Io, DatasetGraphErrorsNameFileAndRecord) {
  const auto tile = [](const std::string& text) {
    return io::DatasetTile{"t", "test-000000", {{"graph.json", std::vector<uint8_t>(text.begin(), text.end())}}};
  };
  const std::string bad =
      R"({"nodes":[{"id":1,"u":0,"v":0,"x":0,"y":0}],"edges":[{"source":1,"target":7,"lane_token":"a"}]})";
  try {
    tile_graph(tile(bad));
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), "t.graph.json");
    EXPECT_EQ(e.record(), "/edges/0/target");
  }
  EXPECT_THROW(tile_graph(tile("{\"nodes\": [")), ParseError);
  EXPECT_THROW(tile(bad).meta(), ParseError);  // no meta.json member: named, not a crash
  // Ids are the file's, edges become indices: 100 → 99 and 98 → 99 are 0 → 1 and 2 → 1.
  const Graph g = tile_graph(tile(graph_doc("t", 0.0)));
  ASSERT_EQ(g.nodes.size(), 3u);
  ASSERT_EQ(g.edges.size(), 2u);
  EXPECT_EQ(g.edges[0], (std::array<int64_t, 2>{0, 1}));
  EXPECT_EQ(g.edges[1], (std::array<int64_t, 2>{2, 1}));
  EXPECT_EQ(g.nodes[2].u, 20.0);
}

TEST(Io, SubmissionStructureErrorsNamePath) {
  const nlohmann::json doc =
      nlohmann::json::parse(R"({"schema_version":"1","tiles":{"a/b":{"nodes":[[0,0]],"edges":[[0,1]]}}})");
  try {
    graphs_from_submission(doc, "s.json");
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_EQ(e.record(), "/tiles/a~1b/edges/0/1");
  }
}

}  // namespace
}  // namespace nsg::metrics

namespace nsg::metrics {
namespace {

// graph.json's edge attributes reach the scorer as edge flags (the per-class recalls); a
// graph written before them gives none, so those recalls are undefined, not "all lanes".
TEST(Io, EdgeAttributesBecomeTheGroundTruthsEdgeFlags) {
  graph::TileGraph tile;
  tile.nodes = {{0, 0.0, 0.0, 0.0, 0.0, graph::Junction::kNone},
                {1, 10.0, 0.0, 2.0, 0.0, graph::Junction::kNone},
                {2, 20.0, 0.0, 4.0, 0.0, graph::Junction::kNone}};
  tile.edges.resize(2);
  tile.edges[0] = {0, 1, "lane", false, false, graph::Turn::kStraight};
  tile.edges[1] = {1, 2, "connector", true, true, graph::Turn::kLeft};
  EXPECT_EQ(graph_of_tile(tile).edge_flags, (std::vector<uint8_t>{0, kEdgeConnector | kEdgeInIntersection}));
  tile.has_edge_attributes = false;
  EXPECT_TRUE(graph_of_tile(tile).edge_flags.empty());
}

}  // namespace
}  // namespace nsg::metrics
