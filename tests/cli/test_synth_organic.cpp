// The organic sample world end to end with the real binary: `nsgraph synth` writes a release
// from samples/synth/organic-tiny.json that `nsgraph generate` tiles and `nsgraph validate`
// accepts (the grid's tiny.json takes the same road through tests/unit/pipeline).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "nsg/core/files.h"
#include "test_support.h"

namespace nsg {
namespace {

namespace fs = std::filesystem;

TEST(CliSynthOrganic, SynthGenerateAndValidateAcceptTheOrganicSample) {
  test::TempDir tmp("synth-organic");
  const fs::path release = tmp / "release", dataset = tmp / "dataset";
  const test::CommandResult synth =
      test::run_nsgraph({"synth", "-q", "--config", (test::source_dir() / "samples/synth/organic-tiny.json").string(),
                         "--out", release.string(), "--threads", "2"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  ASSERT_TRUE(fs::exists(release / "maps" / "expansion" / "boston-seaport.json"));
  // One test region over the whole map, so every scene's tiles count.
  test::write_text(tmp / "generate.json", R"({
  "schema_version": "1",
  "seed": 11,
  "splits": {"buffer_m": 25.6, "regions": {"boston-seaport": [
    {"name": "all", "split": "test", "bounds_m": [0.0, 0.0, 600.0, 400.0]}]}},
  "crops": {"size_px": 128, "min_lidar_coverage": 0.1, "random_per_km2": 3000.0},
  "output": {"tiles_per_shard": 4}
})");
  const test::CommandResult generate =
      test::run_nsgraph({"generate", "-q", "--config", (tmp / "generate.json").string(), "--dataroot", release.string(),
                         "--version", "v1.0-mini", "--out", dataset.string(), "--threads", "2"});
  ASSERT_EQ(generate.exit_code, 0) << generate.err;
  const nlohmann::json manifest = nlohmann::json::parse(read_file(dataset / "manifest.json"));
  EXPECT_GT(manifest["counts"]["total_tiles"].get<int>(), 4) << manifest["counts"].dump();
  const test::CommandResult validate = test::run_nsgraph({"validate", dataset.string()});
  EXPECT_EQ(validate.exit_code, 0) << validate.out << validate.err;
  EXPECT_NE(validate.out.find("0 error(s), 0 warning(s)"), std::string::npos) << validate.out;
}

}  // namespace
}  // namespace nsg
