// Hostile shards, crafted header by header with Python's tarfile: index_tar (the Python
// Dataset's reader) and TarReader (validate, score) refuse the same archives, naming the
// file and the member, and neither loops or allocates from a hostile size.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>

#include "nsg/core/error.h"
#include "nsg/io/dataset.h"
#include "nsg/io/tar.h"
#include "nsg/io/tar_index.h"
#include "nsg/io/tile_index.h"
#include "manifest_fixture.h"
#include "test_support.h"

namespace nsg::io {
namespace {

namespace fs = std::filesystem;

// Writes a tar with Python's tarfile; `members` is Python code adding members to `t`
// (helper add(name, data, **fields) and the tarfile module in scope).
void python_tar(const fs::path& path, const std::string& members) {
  const auto r = nsg::test::run_program({"/usr/bin/python3", "-c",
                                         "import io, sys, tarfile\n"
                                         "def add(t, name, data=b'x', **fields):\n"
                                         "    m = tarfile.TarInfo(name); m.size = len(data)\n"
                                         "    for k, v in fields.items(): setattr(m, k, v)\n"
                                         "    t.addfile(m, io.BytesIO(data))\n"
                                         "with tarfile.open(sys.argv[1], 'w', format=tarfile.PAX_FORMAT) as t:\n" +
                                             members,
                                         path.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// Both readers refuse `path` with a ParseError whose message holds `needle`.
void expect_refused(const fs::path& path, const std::string& needle) {
  const auto start = std::chrono::steady_clock::now();
  try {
    index_tar(path);
    ADD_FAILURE() << "index_tar accepted " << path;
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
  try {
    TarReader reader(path);
    TarMember m;
    while (reader.next(m)) {
    }
    ADD_FAILURE() << "TarReader accepted " << path;
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(HostileTar, PaxSizeThatWrapsTheOffsetIsRefused) {
  nsg::test::TempDir dir("io-hostile-size");
  // pax header (512 + 512 bytes), then the member header: its data starts at byte 1536;
  // a size of 2^64 - 1536 made data + size wrap to 0 and the index loop forever.
  python_tar(dir / "wrap.tar",
             "    m = tarfile.TarInfo('k-test-000000.meta.json'); m.size = 1\n"
             "    m.pax_headers = {'size': str(2**64 - 1536)}\n"
             "    t.addfile(m, io.BytesIO(b'x'))\n");
  try {
    index_tar(dir / "wrap.tar");
    FAIL() << "indexed";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("k-test-000000.meta.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("within the archive"), std::string::npos) << e.what();
  }
  python_tar(dir / "digits.tar",
             "    m = tarfile.TarInfo('k-test-000000.meta.json'); m.size = 1\n"
             "    m.pax_headers = {'size': '99999999999999999999999'}\n"
             "    t.addfile(m, io.BytesIO(b'x'))\n");
  EXPECT_THROW(index_tar(dir / "digits.tar"), ParseError);
}

TEST(HostileTar, UnsafeNamesLinksAndDuplicatesAreRefused) {
  nsg::test::TempDir dir("io-hostile-names");
  python_tar(dir / "dotdot.tar", "    add(t, '../k-test-000000.meta.json')\n");
  expect_refused(dir / "dotdot.tar", "'..'");
  python_tar(dir / "abs.tar", "    add(t, '/tmp/k-test-000000.meta.json')\n");
  expect_refused(dir / "abs.tar", "relative member name");
  python_tar(dir / "link.tar",
             "    add(t, 'k-test-000000.meta.json')\n"
             "    add(t, 'k-test-000000.rgb.tif', b'', type=tarfile.SYMTYPE, linkname='/etc/passwd')\n");
  expect_refused(dir / "link.tar", "symbolic link");
  python_tar(dir / "dup.tar",
             "    add(t, 'k-test-000000.meta.json', b'{}')\n"
             "    add(t, 'k-test-000000.meta.json', b'[]')\n");
  expect_refused(dir / "dup.tar", "each member name once");
}

TEST(HostileTar, ManifestPathsOutsideTheDatasetAreRefused) {
  nsg::test::TempDir dir("io-hostile-manifest");
  fs::create_directories(dir / "ds");
  python_tar(dir / "outside.tar", "    add(t, 'k-test-000000.meta.json', b'{}')\n");
  std::ofstream(dir / "ds/manifest.json")
      << nsg::test::complete_manifest(
             nlohmann::json::parse(
                 R"([{"name": "test-000000", "split": "test", "file": "../outside.tar", "tiles": 1}])"))
             .dump();
  try {
    SplitIndex(dir / "ds", "test");
    FAIL() << "a shard outside the dataset was read";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("manifest.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("../outside.tar"), std::string::npos) << e.what();
  }
  // The manifest's reader refuses it, naming the field: no reader of the dataset gets it.
  try {
    Dataset::open(dir / "ds");
    FAIL() << "a shard outside the dataset was listed";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.record(), "/shards/0/file");
  }
}

}  // namespace
}  // namespace nsg::io
