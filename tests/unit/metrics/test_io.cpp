// Ground-truth readers: submission-format files, dataset folders and WebDataset tars.
#include <archive.h>
#include <archive_entry.h>
#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/metrics/io.h"
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

TEST(Io, FolderLayout) {
  nsg::test::TempDir dir("metrics-folder");
  for (const char* key : {"boston-test-000001", "boston-test-000000"})
    nsg::test::write_text(dir / "tiles" / "test" / key / (std::string(key) + ".graph.json"),
                          graph_doc(key, key[17] == '1' ? 1.0 : 0.0));
  nsg::test::write_text(dir / "tiles" / "train" / "x" / "x.graph.json", "not read");
  const GraphSet set = load_ground_truth(dir.path(), "test");
  ASSERT_EQ(set.size(), 2u);
  expect_tile(set.at("boston-test-000000"), 0.0);
  expect_tile(set.at("boston-test-000001"), 1.0);
  EXPECT_THROW(load_ground_truth(dir.path(), "val"), IoError);
}

TEST(Io, WebDatasetShards) {
  nsg::test::TempDir dir("metrics-tar");
  fs::create_directories(dir / "shards");
  write_tar(dir / "shards" / "test-000000.tar", {{"k0.graph.json", graph_doc("k0", 0.0)}, {"k0.meta.json", "{}"}});
  write_tar(dir / "shards" / "test-000001.tar", {{"k1.graph.json", graph_doc("k1", 1.0)}});
  write_tar(dir / "shards" / "train-000000.tar", {{"t.graph.json", "garbage"}});
  const GraphSet set = load_dataset_split(dir.path(), "test");
  ASSERT_EQ(set.size(), 2u);
  expect_tile(set.at("k0"), 0.0);
  expect_tile(set.at("k1"), 1.0);
}

TEST(Io, DatasetGraphErrorsNameFileAndRecord) {
  const std::string bad = R"({"nodes":[{"id":1,"u":0,"v":0}],"edges":[{"source":1,"target":7}]})";
  try {
    graph_from_dataset_json(bad, "t.graph.json");
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), "t.graph.json");
    EXPECT_EQ(e.record(), "/edges/0/target");
  }
  EXPECT_THROW(graph_from_dataset_json("{\"nodes\": [", "t.graph.json"), ParseError);
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
