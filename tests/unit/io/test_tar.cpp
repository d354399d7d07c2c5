// WebDataset tar shards: round trip, reproducible bytes, Python's tarfile as an independent
// reader, truncation, and the temp-file contract.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/io/tar.h"
#include "test_support.h"

namespace nsg::io {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> bytes_of(size_t n, uint8_t seed) {
  std::vector<uint8_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<uint8_t>(seed + i * 31 + (i >> 8));
  return v;
}

// Sizes around the 512-byte block edges, an empty member, and a name too long for ustar's
// 100-byte name field (needs the prefix field or a pax header).
std::vector<TarMember> sample_members() {
  const std::string long_name = std::string(120, 'k') + ".graph.json";
  return {{"boston-seaport-train-000000.lidar.tif", bytes_of(100000, 1)},
          {"boston-seaport-train-000000.meta.json", bytes_of(0, 2)},
          {"boston-seaport-train-000000.rgb.tif", bytes_of(511, 3)},
          {"boston-seaport-train-000001.lidar.tif", bytes_of(512, 4)},
          {"boston-seaport-train-000001.rgb.tif", bytes_of(513, 5)},
          {long_name, bytes_of(1, 6)}};
}

TarWriter::Result write_tar(const fs::path& path, const std::vector<TarMember>& members) {
  TarWriter w(path);
  for (const auto& m : members) w.add(m.name, m.bytes);
  return w.finish();
}

std::vector<TarMember> read_all(const fs::path& path) {
  TarReader r(path);
  std::vector<TarMember> out;
  TarMember m;
  while (r.next(m)) out.push_back(m);
  return out;
}

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> v;
  for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename());
  return v;
}

TEST(Tar, RoundTripKeepsOrderNamesAndBytes) {
  nsg::test::TempDir dir("io-tar");
  const auto members = sample_members();
  const auto path = dir / "shards" / "train-000000.tar";
  const auto result = write_tar(path, members);
  EXPECT_EQ(result.members, members.size());
  EXPECT_EQ(result.bytes, fs::file_size(path));
  EXPECT_EQ(result.bytes % 512, 0u);
  EXPECT_EQ(result.sha256_hex, sha256_file(path));
  const auto back = read_all(path);
  ASSERT_EQ(back.size(), members.size());
  for (size_t i = 0; i < members.size(); ++i) {
    EXPECT_EQ(back[i].name, members[i].name);
    EXPECT_TRUE(back[i].bytes == members[i].bytes) << members[i].name;
  }
  // Only the final file remains: the temp was renamed.
  EXPECT_EQ(files_in(dir / "shards"), std::vector<fs::path>{"train-000000.tar"});
}

TEST(Tar, SameMembersGiveIdenticalBytes) {
  nsg::test::TempDir dir("io-tar-repro");
  const auto a = write_tar(dir / "a.tar", sample_members());
  const auto b = write_tar(dir / "b.tar", sample_members());
  EXPECT_EQ(a.sha256_hex, b.sha256_hex);
  EXPECT_EQ(nsg::test::read_text(dir / "a.tar"), nsg::test::read_text(dir / "b.tar"));
  auto changed = sample_members();
  changed[2].bytes[7] ^= 1;
  EXPECT_NE(write_tar(dir / "c.tar", changed).sha256_hex, a.sha256_hex);
}

// Python's tarfile (what WebDataset uses) lists the members with the fixed metadata.
TEST(Tar, PythonTarfileListsMembers) {
  nsg::test::TempDir dir("io-tar-py");
  const auto members = sample_members();
  write_tar(dir / "s.tar", members);
  const auto r =
      nsg::test::run_program({"/usr/bin/python3", "-c",
                              "import sys, tarfile\n"
                              "with tarfile.open(sys.argv[1]) as t:\n"
                              "    for m in t:\n"
                              "        data = t.extractfile(m).read()\n"
                              "        print(m.name, m.size, len(data), m.mtime, m.uid, m.gid, oct(m.mode),\n"
                              "              repr(m.uname), repr(m.gname), m.isfile())\n",
                              (dir / "s.tar").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string expected;
  for (const auto& m : members) {
    const std::string n = std::to_string(m.bytes.size());
    expected += m.name + " " + n + " " + n + " 0 0 0 0o644 '' '' True\n";
  }
  EXPECT_EQ(r.out, expected);
}

void expect_parse_error(const fs::path& path, const std::string& record_part) {
  try {
    read_all(path);
    FAIL() << "expected ParseError for " << path;
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_NE(e.record().find(record_part), std::string::npos) << e.what();
  }
}

TEST(Tar, TruncatedArchiveIsAParseErrorNamingFileAndMember) {
  nsg::test::TempDir dir("io-tar-cut");
  const auto members = sample_members();
  const auto full = dir / "full.tar";
  write_tar(full, members);
  const std::string bytes = nsg::test::read_text(full);
  auto cut_at = [&](size_t n) {
    const auto p = dir / ("cut-" + std::to_string(n) + ".tar");
    nsg::test::write_text(p, bytes.substr(0, n));
    return p;
  };
  // Inside the first member's data: the member is named.
  expect_parse_error(cut_at(512 + 5000), "boston-seaport-train-000000.lidar.tif");
  // Inside the second header.
  expect_parse_error(cut_at(512 + 100352 + 100), "");
  // Exactly at a member boundary (what libarchive alone would accept): the end marker is
  // missing after the last complete member.
  expect_parse_error(cut_at(512 + 100352), "boston-seaport-train-000000.lidar.tif");
  // An empty file is not a tar either.
  expect_parse_error(cut_at(0), "");
}

TEST(Tar, DamagedHeaderIsAParseError) {
  nsg::test::TempDir dir("io-tar-bad");
  write_tar(dir / "s.tar", sample_members());
  std::string bytes = nsg::test::read_text(dir / "s.tar");
  bytes[512 + 100352 + 130] ^= 0x11;  // inside the second header's size/mtime fields
  nsg::test::write_text(dir / "bad.tar", bytes);
  expect_parse_error(dir / "bad.tar", "");
}

TEST(Tar, UnfinishedWriterLeavesNoFile) {
  nsg::test::TempDir dir("io-tar-abandon");
  {
    TarWriter w(dir / "x.tar");
    w.add("a.txt", bytes_of(1000, 9));
  }
  EXPECT_TRUE(files_in(dir.path()).empty());
  try {
    TarWriter w(dir / "y.tar");
    w.add("a.txt", bytes_of(10, 9));
    w.add("a.txt", bytes_of(10, 9));  // duplicate: throws, unwinding removes the temp
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("a.txt"), std::string::npos);
  }
  EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(Tar, RejectsUnsafeMemberNamesAndMissingFiles) {
  nsg::test::TempDir dir("io-tar-names");
  TarWriter w(dir / "n.tar");
  const std::vector<uint8_t> one{1};
  EXPECT_THROW(w.add("", one), ConfigError);
  EXPECT_THROW(w.add("/etc/passwd", one), ConfigError);
  EXPECT_THROW(w.add("a/../../b", one), ConfigError);
  EXPECT_THROW(w.add("dir/", one), ConfigError);
  w.add("ok.json", one);
  EXPECT_EQ(w.finish().members, 1u);
  EXPECT_THROW(TarReader(dir / "missing.tar"), IoError);
}

}  // namespace
}  // namespace nsg::io
