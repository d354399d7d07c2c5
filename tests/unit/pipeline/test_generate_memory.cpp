// `generate`'s peak-memory estimate and --max-memory, on the e2e release: the
// estimate is logged before any work, a limit below it refuses the run with exit 2 naming
// the estimate and what would lower it, and nothing is written; a limit above it runs.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>

#include "generate_fixture.h"
#include "nsg/core/error.h"
#include "nsg/core/memory.h"
#include "nsg/core/strings.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace nsg::test {
namespace {

std::vector<std::string> args(const fs::path& out, const std::string& max_memory, const std::string& threads) {
  return {"-v",           "generate",
          "--config",     (source_dir() / "tests/data/generate/e2e.json").string(),
          "--dataroot",   e2e_release().string(),
          "--version",    "v1.0-mini",
          "--out",        out.string(),
          "--layout",     "folder",
          "--threads",    threads,
          "--max-memory", max_memory};
}

// The estimate in bytes from the -v line.
uint64_t logged_estimate(const std::string& err) {
  std::smatch m;
  if (!std::regex_search(err, m, std::regex("estimated peak memory in bytes: (\\d+)"))) return 0;
  return std::stoull(m[1]);
}

TEST(GenerateMemory, AnEstimateAboveTheLimitRefusesTheRunBeforeAnyWork) {
  TempDir dir("gen-memory");
  const CommandResult r = run_nsgraph(args(dir / "out", "20M", "2"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--max-memory: a run that fits in 20.0 MB; the estimated peak is"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("LiDAR layer"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("What would lower it:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\n  - fewer threads (--threads)"), std::string::npos) << "one line each:\n" << r.err;
  EXPECT_NE(r.err.find("--num-shards"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("accumulating LiDAR"), std::string::npos) << "refused after the heavy work started:\n" << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/manifest.json"));
  EXPECT_GT(logged_estimate(r.err), 20'000'000u);
}

// Without --max-memory the limit is the memory available (the machine's, or the cgroup's
// when lower), so a run estimated beyond it is refused by default; the refusal itself is
// the test above.
TEST(GenerateMemory, TheDefaultLimitIsTheAvailableMemory) {
  const uint64_t available = available_memory_bytes();
  ASSERT_GT(available, 0u);
  TempDir dir("gen-memory-default");
  std::vector<std::string> a = args(dir / "out", "", "2");
  a.resize(a.size() - 2);  // no --max-memory
  const CommandResult r = run_nsgraph(a);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(strprintf("generate: memory limit in bytes: %llu (the memory available)",
                                 static_cast<unsigned long long>(available))),
            std::string::npos)
      << r.err;
}

// The estimate is within ±25 % of the measured peak (the child's peak resident memory, as
// /usr/bin/time reports it) on the e2e world, at 1 and 2 threads, with the semantic layer
// from masks and from lidarseg; `make bench` checks the same band on the city and demo worlds.
TEST(GenerateMemory, ALimitAboveTheEstimateRunsAndTheEstimateIsWithin25PercentOfThePeak) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> runs = {
      {"1", {}}, {"2", {}}, {"2", {"--set", "camera.semantic_source=lidarseg"}}};
  for (const auto& [threads, extra] : runs) {
    SCOPED_TRACE(threads + " thread(s)" + (extra.empty() ? "" : ", lidarseg"));
    TempDir dir("gen-memory-ok");
    std::vector<std::string> a = args(dir / "out", "4GiB", threads);
    a.insert(a.end(), extra.begin(), extra.end());
    const CommandResult r = run_nsgraph(a);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "out/manifest.json"));
    EXPECT_NE(r.err.find("generate: estimated peak memory "), std::string::npos) << r.err;
    const double estimate = static_cast<double>(logged_estimate(r.err)), peak = static_cast<double>(r.peak_rss_bytes);
    std::printf("[ figures ] e2e world, %s thread(s)%s: estimate %.1f MB, peak %.1f MB = %.2fx\n", threads.c_str(),
                extra.empty() ? "" : ", lidarseg", estimate / 1e6, peak / 1e6, estimate / peak);
    ASSERT_GT(peak, 0.0);
    EXPECT_GE(estimate / peak, 0.75);
    EXPECT_LE(estimate / peak, 1.25);
  }
}

TEST(GenerateMemory, SizesParseWithTheirUnitsAndBadOnesNameTheOption) {
  EXPECT_EQ(parse_memory_size("16G", "--max-memory"), 16'000'000'000u);
  EXPECT_EQ(parse_memory_size("1.5GiB", "--max-memory"), 1'610'612'736u);
  EXPECT_EQ(parse_memory_size("800M", "--max-memory"), 800'000'000u);
  EXPECT_EQ(parse_memory_size("512 KiB", "--max-memory"), 524'288u);
  EXPECT_EQ(parse_memory_size("2048", "--max-memory"), 2048u);
  for (const char* bad : {"", "G", "16Q", "-1G", "0", "nan", "1e30G"}) {
    try {
      parse_memory_size(bad, "--max-memory");
      ADD_FAILURE() << "accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("--max-memory"), std::string::npos) << e.what();
    }
  }
  TempDir dir("gen-memory-bad");
  const CommandResult r = run_nsgraph(args(dir / "out", "lots", "1"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("a memory size such as 800M"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nsg::test
