// Random access into tar shards: index_tar against TarReader and Python's tarfile (pax and
// GNU long names, directories), refusals of damaged archives, SplitIndex over a small
// hand-made dataset.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <unistd.h>

#include <fstream>

#include "nsg/core/error.h"
#include "nsg/io/tar.h"
#include "nsg/io/tar_index.h"
#include "nsg/io/tile_index.h"
#include "manifest_fixture.h"
#include "test_support.h"

namespace nsg::io {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> bytes_of(size_t n, uint8_t seed) {
  std::vector<uint8_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<uint8_t>(seed + i * 29 + (i >> 9));
  return v;
}

void write_tar(const fs::path& path, const std::vector<TarMember>& members) {
  TarWriter w(path);
  for (const auto& m : members) w.add(m.name, m.bytes);
  w.finish();
}

std::vector<uint8_t> read_entry(const fs::path& path, const TarIndexEntry& e) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  std::vector<uint8_t> out(e.size);
  read_at(fd, e.offset, out.data(), out.size(), path.string(), e.name);
  ::close(fd);
  return out;
}

// Every member TarReader streams, with the same bytes at the indexed offsets.
void expect_index_matches_reader(const fs::path& path) {
  const std::vector<TarIndexEntry> index = index_tar(path);
  TarReader reader(path);
  TarMember m;
  size_t k = 0;
  while (reader.next(m)) {
    ASSERT_LT(k, index.size());
    EXPECT_EQ(index[k].name, m.name);
    EXPECT_EQ(read_entry(path, index[k]), m.bytes) << m.name;
    ++k;
  }
  EXPECT_EQ(k, index.size());
}

TEST(TarIndex, OffsetsOfOurShardsIncludingPaxLongNames) {
  nsg::test::TempDir dir("io-tar-index");
  const std::string long_name = std::string(130, 'k') + ".graph.json";
  write_tar(dir / "s.tar", {{"a-test-000000.lidar.tif", bytes_of(100000, 1)},
                            {"a-test-000000.meta.json", bytes_of(0, 2)},
                            {"a-test-000001.rgb.tif", bytes_of(511, 3)},
                            {long_name, bytes_of(513, 4)}});
  expect_index_matches_reader(dir / "s.tar");
  EXPECT_EQ(index_tar(dir / "s.tar").back().name, long_name);
}

TEST(TarIndex, GnuAndPaxArchivesOfPythonTarfile) {
  nsg::test::TempDir dir("io-tar-index-py");
  for (const std::string format : {"GNU_FORMAT", "PAX_FORMAT", "USTAR_FORMAT"}) {
    const fs::path tar = dir / (format + ".tar");
    const auto r =
        nsg::test::run_program({"/usr/bin/python3", "-c",
                                "import io, sys, tarfile\n"
                                "with tarfile.open(sys.argv[1], 'w', format=getattr(tarfile, sys.argv[2])) as t:\n"
                                "    d = tarfile.TarInfo('folder'); d.type = tarfile.DIRTYPE; t.addfile(d)\n"
                                "    names = ['folder/k-test-000000.lidar.tif', 'k-test-000000.meta.json']\n"
                                "    if sys.argv[2] != 'USTAR_FORMAT': names.append('x' * 150 + '.rgb.tif')\n"
                                "    for i, n in enumerate(names):\n"
                                "        data = bytes((i * 7 + j) % 251 for j in range(1000 * i + 3))\n"
                                "        m = tarfile.TarInfo(n); m.size = len(data); t.addfile(m, io.BytesIO(data))\n",
                                tar.string(), format});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    expect_index_matches_reader(tar);
    EXPECT_EQ(index_tar(tar).front().name, "folder/k-test-000000.lidar.tif") << format;
  }
}

TEST(TarIndex, RefusesDamagedArchives) {
  nsg::test::TempDir dir("io-tar-index-bad");
  write_tar(dir / "s.tar", {{"a-test-000000.lidar.tif", bytes_of(5000, 1)}});
  const auto size = fs::file_size(dir / "s.tar");
  fs::copy_file(dir / "s.tar", dir / "cut.tar");
  fs::resize_file(dir / "cut.tar", 2048);  // inside the member
  try {
    index_tar(dir / "cut.tar");
    FAIL() << "a truncated tar was indexed";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.tar"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a-test-000000.lidar.tif"), std::string::npos) << e.what();
  }
  std::fstream f(dir / "s.tar", std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(10);
  f.put('#');  // the name changes, the checksum no longer fits
  f.close();
  EXPECT_THROW(index_tar(dir / "s.tar"), ParseError);
  EXPECT_EQ(fs::file_size(dir / "s.tar"), size);
  EXPECT_THROW(index_tar(dir / "absent.tar"), IoError);
}

// A dataset of two test shards and one train shard, members as generate writes them.
fs::path small_dataset(const fs::path& root, int tiles_claimed_by_second = 1) {
  fs::create_directories(root / "shards");
  write_tar(root / "shards/test-000000.tar", {{"l-test-000000.lidar.tif", bytes_of(10, 1)},
                                              {"l-test-000000.meta.json", bytes_of(3, 2)},
                                              {"l-test-000001.lidar.tif", bytes_of(20, 3)},
                                              {"l-test-000001.meta.json", bytes_of(4, 4)}});
  write_tar(root / "shards/test-000001.tar", {{"l-test-000002.lidar.tif", bytes_of(30, 5)}});
  write_tar(root / "shards/train-000000.tar", {{"l-train-000000.lidar.tif", bytes_of(40, 6)}});
  std::ofstream(root / "manifest.json")
      << nsg::test::complete_manifest(
             {{{"name", "test-000000"}, {"split", "test"}, {"file", "shards/test-000000.tar"}, {"tiles", 2}},
              {{"name", "test-000001"},
               {"split", "test"},
               {"file", "shards/test-000001.tar"},
               {"tiles", tiles_claimed_by_second}},
              {{"name", "train-000000"}, {"split", "train"}, {"file", "shards/train-000000.tar"}, {"tiles", 1}}})
             .dump();
  return root;
}

TEST(SplitIndex, KeysInManifestOrderAndRandomAccess) {
  nsg::test::TempDir dir("io-split-index");
  const SplitIndex index(small_dataset(dir.path()), "test");
  ASSERT_EQ(index.size(), 3u);
  EXPECT_EQ(index.key(0), "l-test-000000");
  EXPECT_EQ(index.key(2), "l-test-000002");
  EXPECT_EQ(index.shard_name(2), "test-000001");
  EXPECT_EQ(index.suffixes(1), (std::vector<std::string>{"lidar.tif", "meta.json"}));
  EXPECT_EQ(index.read(2).files.at("lidar.tif"), bytes_of(30, 5));
  const DatasetTile t = index.read(1, {"meta.json"});
  EXPECT_EQ(t.files.size(), 1u);
  EXPECT_EQ(t.files.at("meta.json"), bytes_of(4, 4));
  EXPECT_THROW(index.read(2, {"meta.json"}), ParseError);  // that tile has no meta
  EXPECT_THROW(index.read(3), ConfigError);
}

TEST(SplitIndex, NamesTheSplitsAndTheTileCounts) {
  nsg::test::TempDir dir("io-split-index-bad");
  small_dataset(dir / "a");
  try {
    SplitIndex(dir / "a", "val");
    FAIL() << "an unknown split was opened";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("the dataset has: test, train"), std::string::npos) << e.what();
  }
  small_dataset(dir / "b", 5);
  EXPECT_THROW(SplitIndex(dir / "b", "test"), DataError);
  EXPECT_THROW(SplitIndex(dir / "absent", "test"), IoError);
}

}  // namespace
}  // namespace nsg::io
