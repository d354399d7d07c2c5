// `generate`'s peak-memory estimate and --max-memory, on the e2e release: the
// estimate is logged before any work, a limit below it refuses the run with exit 2 naming
// the estimate and what would lower it, and nothing is written; a limit above it runs.
#include <gtest/gtest.h>

#include <cstdio>
#include <chrono>
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
      {"1", {}},
      {"2", {}},
      {"2", {"--set", "camera.semantic_source=lidarseg"}},
      {"2", {"--set", "graph.max_spacing_m=0.1"}}};  // the graph 20x denser
  for (const auto& [threads, extra] : runs) {
    SCOPED_TRACE(threads + " thread(s)" + (extra.empty() ? "" : ", " + extra[1]));
    TempDir dir("gen-memory-ok");
    std::vector<std::string> a = args(dir / "out", "4GiB", threads);
    a.insert(a.end(), extra.begin(), extra.end());
    const CommandResult r = run_nsgraph(a);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "out/manifest.json"));
    EXPECT_NE(r.err.find("generate: estimated peak memory "), std::string::npos) << r.err;
    const double estimate = static_cast<double>(logged_estimate(r.err)), peak = static_cast<double>(r.peak_rss_bytes);
    std::printf("[ figures ] e2e world, %s thread(s)%s: estimate %.1f MB, peak %.1f MB = %.2fx\n", threads.c_str(),
                extra.empty() ? "" : (", " + extra[1]).c_str(), estimate / 1e6, peak / 1e6, estimate / peak);
    ASSERT_GT(peak, 0.0);
    EXPECT_GE(estimate / peak, 0.75);
    EXPECT_LE(estimate / peak, 1.25);
  }
}

// The plan's terms against what the run measured, each on its own (the total above hides
// a term that is small on this world): the LiDAR blocks and covered cells it predicts
// (kReachedBlockFraction, the coverage fit) and the packed block's bookkeeping (a
// constant that drifts from the layer's real cost, e.g. cut to a tenth, fails here).
TEST(GenerateMemory, EachPlanTermAgreesWithTheRunsMeasure) {
  TempDir dir("gen-memory-terms");
  const CommandResult r = run_nsgraph(args(dir / "out", "4GiB", "2"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::smatch plan, run;
  ASSERT_TRUE(std::regex_search(r.err, plan,
                                std::regex("memory plan: location=(\\S+) lidar_blocks=(\\d+) covered_cells=(\\d+) "
                                           "packed_block_bytes=(\\d+)")))
      << r.err;
  ASSERT_TRUE(std::regex_search(r.err, run,
                                std::regex(plan[1].str() + ": LiDAR accumulated: (\\d+) blocks, (\\d+) covered cells, "
                                                           "(\\d+) B a block besides its cells")))
      << r.err;
  const auto ratio = [](const std::ssub_match& est, const std::ssub_match& measured) {
    return std::stod(est.str()) / std::stod(measured.str());
  };
  const double blocks = ratio(plan[2], run[1]), cells = ratio(plan[3], run[2]), block_bytes = ratio(plan[4], run[3]);
  std::printf("[ figures ] e2e world, estimate / run: LiDAR blocks %.2f, covered cells %.2f, packed block bytes %.2f\n",
              blocks, cells, block_bytes);
  EXPECT_GE(blocks, 0.67);
  EXPECT_LE(blocks, 1.5);
  EXPECT_GE(cells, 0.6);
  EXPECT_LE(cells, 1.6);
  EXPECT_GE(block_bytes, 0.67);
  EXPECT_LE(block_bytes, 1.5);
}

// Settings that scale work without bound are refused by name where they are read, and a
// resolution that needs terabytes is estimated at once (on cells of 1/16 of the LiDAR
// range, not one per block: it took minutes) and refused by default.
TEST(GenerateMemory, UnboundedSettingsAreRefusedByNameAndAFineResolutionIsEstimatedAtOnce) {
  for (const char* bad : {"lidar.max_range_m=1e9", "camera.view_radius_m=1e9", "graph.max_spacing_m=1e-5",
                          "crops.random_total=1000000000"}) {
    SCOPED_TRACE(bad);
    TempDir dir("gen-memory-bad");
    std::vector<std::string> a = args(dir / "out", "4GiB", "1");
    a.insert(a.end(), {"--set", bad});
    const CommandResult r = run_nsgraph(a);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(std::string(bad).substr(0, std::string(bad).find('='))), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
  TempDir dir("gen-memory-fine");
  std::vector<std::string> a = args(dir / "out", "", "1");
  a.resize(a.size() - 2);  // no --max-memory: the memory available
  a.insert(a.end(), {"--set", "resolution_m=0.001"});
  const auto start = std::chrono::steady_clock::now();
  const CommandResult r = run_nsgraph(a);
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--max-memory"), std::string::npos) << r.err;
  EXPECT_GT(logged_estimate(r.err), 100'000'000'000u);  // hundreds of GB
  EXPECT_LT(took.count(), 20.0);                        // it took about two minutes; now ~0.2 s
  EXPECT_FALSE(fs::exists(dir / "out/manifest.json"));
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
