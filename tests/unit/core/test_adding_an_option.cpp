// docs/architecture.md "Adding an option", done: a `crops.foo_m` key declared with the
// declaration line the guide shows (tests/repo/check_repository.py holds the guide's line
// and the one below to the same text), and everything the guide says follows from it
// without more code — the config file, --set, flags after --set, the range error naming
// the key and its source, the resolved config, --list-options, the JSON Schema and check().
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/options.h"
#include "test_support.h"

namespace nsg::test {
namespace {

// The guide's options struct, cut down to the new field (its default is the initializer).
struct CropOptions {
  double foo_m = 1.5;
};

const options::Table<CropOptions>& crop_option_table() {
  static const options::Table<CropOptions> table = [] {
    options::Table<CropOptions> t;
    // clang-format off
    t.number("crops.foo_m", &CropOptions::foo_m).unit("m").range(options::at_least(0)).help("...");
    // clang-format on
    return t;
  }();
  return table;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(AddingAnOption, TheDeclarationLineGivesFileSetFlagsAndChecks) {
  TempDir dir;
  const auto file = dir.path() / "config.json";
  write_text(file, R"({"crops": {"foo_m": 2.5}})");
  options::Origins origins;
  const CropOptions from_file = options::resolve_config(crop_option_table(), file, {}, {}, "crops.foo_m=1", origins);
  EXPECT_DOUBLE_EQ(from_file.foo_m, 2.5);
  EXPECT_EQ(origins.at("crops.foo_m"), file.string());

  // The file < --set < a flag standing for the key, whatever their order on the command line.
  const options::FlagValue flag{"--foo", "crops.foo_m", 4.0};
  const CropOptions resolved =
      options::resolve_config(crop_option_table(), file, {"crops.foo_m=3"}, {flag}, "crops.foo_m=1", origins);
  EXPECT_DOUBLE_EQ(resolved.foo_m, 4.0);
  EXPECT_EQ(origins.at("crops.foo_m"), "--foo");

  // The range is checked when the value is set, naming the key and where the value came from.
  const std::string bad_set = message_of([] {
    options::Origins o;
    options::resolve_config(crop_option_table(), {}, {"crops.foo_m=-1"}, {}, "crops.foo_m=1", o);
  });
  EXPECT_NE(bad_set.find("crops.foo_m"), std::string::npos) << bad_set;
  EXPECT_NE(bad_set.find("--set"), std::string::npos) << bad_set;
  EXPECT_NE(bad_set.find("≥ 0"), std::string::npos) << bad_set;
  write_text(file, R"({"crops": {"foo": 2.5}})");
  const std::string unknown = message_of([&] {
    options::Origins o;
    options::resolve_config(crop_option_table(), file, {}, {}, "crops.foo_m=1", o);
  });
  EXPECT_NE(unknown.find("crops.foo_m"), std::string::npos) << "a did-you-mean: " << unknown;

  // A struct built in code is checked by the same declaration.
  CropOptions built;
  built.foo_m = -2.0;
  EXPECT_THROW(crop_option_table().check(built), ConfigError);
}

TEST(AddingAnOption, TheDeclarationLineGivesListingsSchemaAndResolvedConfig) {
  const CropOptions defaults;
  const options::OrderedJson resolved = crop_option_table().to_json(defaults);
  EXPECT_EQ(resolved.dump(), R"({"crops":{"foo_m":1.5}})");

  const std::vector<options::Spec> specs = crop_option_table().specs();
  const std::string md = options::list_options(specs, resolved, "md");
  EXPECT_NE(md.find("crops.foo_m"), std::string::npos) << md;
  EXPECT_NE(md.find("1.5"), std::string::npos) << md;
  const options::OrderedJson listed = options::OrderedJson::parse(options::list_options(specs, resolved, "json"));
  ASSERT_EQ(listed.size(), 1u) << listed.dump();
  EXPECT_EQ(listed[0]["unit"], "m") << listed.dump();

  const options::OrderedJson schema = options::config_schema(specs, "foo.schema.json", "foo", "the guide's example");
  const options::OrderedJson foo = schema["properties"]["crops"]["properties"]["foo_m"];
  EXPECT_EQ(foo["type"], "number") << schema.dump();
  EXPECT_EQ(foo["minimum"], 0) << schema.dump();
  EXPECT_EQ(schema["properties"]["crops"]["additionalProperties"], false) << schema.dump();
}

}  // namespace
}  // namespace nsg::test
