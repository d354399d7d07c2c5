// Disk full during `generate`: the run is capped by RLIMIT_FSIZE with SIGXFSZ
// ignored, so a large write fails with EFBIG just as it would with ENOSPC (the cap is per
// file, so where it bites is chosen by the file sizes). The run must fail with a clear
// message, leave nothing incomplete visible (every visible shard is byte for byte the clean
// run's; no temp file), and a rerun without the cap must complete to the clean bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "generate_fixture.h"
#include "nsg/core/sha256.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace nsg::test {
namespace {

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "'\\''";
    else q += c;
  }
  q += '\'';
  return q;
}

// `nsgraph args…` with every file capped at `limit_kib` KiB and SIGXFSZ ignored (inherited
// through exec), so the write returns EFBIG instead of killing the process.
CommandResult run_capped(const std::vector<std::string>& args, uintmax_t limit_kib) {
  std::string line = "trap '' XFSZ; ulimit -f ";
  line += std::to_string(limit_kib);
  line += "; exec ";
  line += shell_quote(nsgraph_exe().string());
  for (const std::string& a : args) {
    line += ' ';
    line += shell_quote(a);
  }
  return run_program({"bash", "-c", line});
}

std::vector<std::string> files_named(const fs::path& dir, const std::string& part) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(part) != std::string::npos) found.push_back(e.path().string());
  return found;
}

uintmax_t largest_file(const fs::path& dir, std::string* name) {
  uintmax_t largest = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.file_size() > largest) largest = e.file_size(), *name = e.path().filename().string();
  return largest;
}

// The first big write of a fresh run is the lane graph (maps/<location>/lanes.geojson,
// ~0.5 MB, larger than any shard): the disk fills there, before any shard exists.
TEST(DiskFull, DuringMapsNothingVisible) {
  const fs::path clean = e2e_dataset();
  const uintmax_t lanes_bytes = fs::file_size(clean / "maps/boston-seaport/lanes.geojson");
  TempDir tmp("disk-full-maps");
  const fs::path out = tmp / "out";
  const CommandResult capped = run_capped(e2e_generate_args(out), lanes_bytes / 2 / 1024);
  EXPECT_EQ(capped.exit_code, 2) << capped.err;
  EXPECT_NE(capped.err.find("lanes.geojson"), std::string::npos) << capped.err;
  EXPECT_NE(capped.err.find("File too large"), std::string::npos) << capped.err;
  EXPECT_FALSE(fs::exists(out / "maps/boston-seaport/lanes.geojson"));
  EXPECT_FALSE(fs::exists(out / "manifest.json"));
  EXPECT_FALSE(fs::exists(out / "shards"));
  EXPECT_EQ(files_named(out, ".tmp-"), std::vector<std::string>{});
  const CommandResult rerun = run_nsgraph(e2e_generate_args(out));
  ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_EQ(tree_hashes(out), tree_hashes(clean));
}

// The disk fills while shards are written: a resumed run (maps done and verified, shards
// and manifest gone) capped just below the largest shard. Every shard written before it
// must be complete, the failing one must not be visible, and the rerun completes.
TEST(DiskFull, DuringShardsOnlyCompleteShardsVisible) {
  const fs::path clean = e2e_dataset();
  std::string largest_name;
  const uintmax_t largest = largest_file(clean / "shards", &largest_name);
  ASSERT_GT(largest, 16u * 1024);

  TempDir tmp("disk-full-shards");
  const fs::path out = tmp / "out";
  const CommandResult first = run_nsgraph(e2e_generate_args(out));
  ASSERT_EQ(first.exit_code, 0) << first.err;
  fs::remove_all(out / "shards");
  fs::remove(out / "manifest.json");

  const CommandResult capped = run_capped(e2e_generate_args(out), (largest - 1) / 1024);
  EXPECT_LT(capped.exit_code, 128) << "killed by signal " << capped.exit_code - 128;
  EXPECT_EQ(capped.exit_code, 2) << capped.err;
  EXPECT_NE(capped.err.find(largest_name), std::string::npos) << "message does not name the shard:\n" << capped.err;
  EXPECT_NE(capped.err.find("File too large"), std::string::npos) << "message does not give the cause:\n" << capped.err;
  EXPECT_FALSE(fs::exists(out / "manifest.json"));
  EXPECT_FALSE(fs::exists(out / "shards" / largest_name));
  for (const auto& e : fs::directory_iterator(out / "shards")) {
    const std::string name = e.path().filename().string();
    if (name.find(".tmp-") != std::string::npos) continue;  // checked below
    EXPECT_EQ(sha256_file(e.path()), sha256_file(clean / "shards" / name)) << name << " is visible but corrupt";
  }
  EXPECT_EQ(files_named(out, ".tmp-"), std::vector<std::string>{});

  const CommandResult rerun = run_nsgraph(e2e_generate_args(out));
  ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_EQ(tree_hashes(out), tree_hashes(clean));
}

// kill -9 as soon as the run has reached a stage (its first file of that stage exists):
// what is visible under shards/ is complete, and a rerun removes the stale temp files and
// completes to the clean bytes.
TEST(KillNine, VisibleShardsCompleteAndRerunCompletes) {
  const fs::path clean = e2e_dataset();
  for (const char* stage : {"parts/*", "maps/*/*", "shards/*"}) {
    SCOPED_TRACE(std::string("kill -9 once ") + stage + " exists");
    TempDir tmp("kill-nine");
    const fs::path out = tmp / "out";
    std::string line = shell_quote(nsgraph_exe().string());
    for (const std::string& a : e2e_generate_args(out)) {
      line += ' ';
      line += shell_quote(a);
    }
    line += " & pid=$!; until compgen -G ";
    line += shell_quote((out / stage).string());
    line +=
        " >/dev/null || ! kill -0 $pid 2>/dev/null; do sleep 0.001; done; kill -9 $pid 2>/dev/null; wait $pid; exit 0";
    ASSERT_EQ(run_program({"bash", "-c", line}).exit_code, 0);
    if (fs::exists(out / "shards"))
      for (const auto& e : fs::directory_iterator(out / "shards")) {
        const std::string name = e.path().filename().string();
        if (name.find(".tmp-") != std::string::npos) continue;  // a killed run may leave these
        EXPECT_EQ(sha256_file(e.path()), sha256_file(clean / "shards" / name)) << name << " is visible but corrupt";
      }
    const CommandResult rerun = run_nsgraph(e2e_generate_args(out));
    ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
    EXPECT_EQ(tree_hashes(out), tree_hashes(clean));
    std::vector<std::string> stale = files_named(out, ".tmp-");
    // Including the done record (parts/share-*.json.tmp-*) of a run killed mid-save.
    EXPECT_EQ(stale, std::vector<std::string>{});
  }
}

}  // namespace
}  // namespace nsg::test
