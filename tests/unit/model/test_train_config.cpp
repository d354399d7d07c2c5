// The train config's declarations: every key read from a file, a flag or --set with its
// range checked once, errors naming the key and its source, and the listing, schema and
// sample generated from the declarations.
#include <gtest/gtest.h>

#include <set>

#include "nsg/core/files.h"
#include "nsg/model/train_options.h"
#include "options_test.h"
#include "test_support.h"

namespace nsg::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST(TrainConfig, EveryKeyRefusesABadValueNamingTheKeyAndItsSource) {
  const std::vector<options::Spec> specs = model::train_option_table().specs();
  ASSERT_GT(specs.size(), 40u);
  expect_every_key_refused_naming_it(
      specs,
      [](const fs::path& file, const std::vector<std::string>& settings) {
        model::resolve_train_config(file, settings);
      },
      "train");
  // Through the binary: a flag names itself and its key.
  CommandResult r = run_nsgraph({"train", "--print-config", "--trees", "0"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--trees: centre_forest.trees: an integer in [1, 1000] (got 0)"), std::string::npos) << r.err;
  r = run_nsgraph({"train", "--print-config", "--set", "extraction.treshold=0.3"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("did you mean 'extraction.threshold'"), std::string::npos) << r.err;
}

// docs/options.md "Precedence": the file, then --set, then the flags (the flag wins).
TEST(TrainConfig, FileThenSetThenFlags) {
  TempDir dir("train-config");
  write_text(dir / "train.json", R"({"variant": "b2", "seed": 5, "anchors": {"neighbours": 3}})");
  const CommandResult r = run_nsgraph({"train", "--print-config", "--config", (dir / "train.json").string(), "--seed",
                                       "6", "--set", "seed=7", "--trees", "9"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json c = json::parse(r.out);
  EXPECT_EQ(c["variant"], "b2");
  EXPECT_EQ(c["seed"], 6);
  EXPECT_EQ(c["anchors"]["neighbours"], 3);
  EXPECT_EQ(c["connection_forest"]["trees"], 9);
  // A code-built ModelOptions is checked by the same declarations.
  model::ModelOptions o;
  o.pairs.radius_px = 1.0;
  try {
    o.validate();
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.record(), "pairs.radius_px");
  }
}

TEST(TrainConfig, ListingSchemaAndSampleEqualTheDeclarations) {
  expect_listed_keys_are_the_config_leaves("train");
  const CommandResult printed = run_nsgraph({"train", "--print-config"});
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_EQ(json::parse(printed.out), json::parse(read_file(source_dir() / "samples/train.json")))
      << "make regen regenerates it: nsgraph train --print-config > samples/train.json";
  const CommandResult schema = run_nsgraph({"train", "--list-options", "--format", "schema"});
  ASSERT_EQ(schema.exit_code, 0) << schema.err;
  EXPECT_EQ(json::parse(schema.out), json::parse(read_file(source_dir() / "schemas/v1/train-config.schema.json")))
      << "make regen regenerates it: nsgraph train --list-options --format schema > "
         "schemas/v1/train-config.schema.json";
  // The sample parses as a config file.
  EXPECT_NO_THROW(model::resolve_train_config(source_dir() / "samples/train.json", {}, {}));
}

}  // namespace
}  // namespace nsg::test
