// One config front end (docs/options.md "Precedence"): every command with a config resolves
// the defaults, then --config, then each --set, then the flags that stand for keys — the
// same rule whatever the command and wherever the flag stands on the line.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace nsg {
namespace {

struct Case {
  std::string command, key, flag;
  nlohmann::json in_file, in_set, in_flag;  // three different values of `key`
};

nlohmann::json resolved(const std::vector<std::string>& args, const std::string& key) {
  const test::CommandResult r = test::run_nsgraph(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return nullptr;
  return nlohmann::json::parse(r.out).at(key);
}

TEST(ConfigPrecedence, FileThenSetThenFlagsForEveryCommand) {
  const std::vector<Case> cases = {
      {"generate", "seed", "--seed", 3, 5, 7},
      {"synth", "seed", "--seed", 3, 5, 7},
      {"train", "seed", "--seed", 3, 5, 7},
      {"frames", "overlap", "--overlap", "keep", "flag", "drop"},
  };
  test::TempDir dir("config-precedence");
  for (const Case& c : cases) {
    SCOPED_TRACE(c.command);
    const std::string file = (dir / (c.command + ".json")).string();
    test::write_text(file, nlohmann::json{{c.key, c.in_file}}.dump());
    const std::string set = c.key + "=" + c.in_set.dump();
    const std::string flag_value = c.in_flag.is_string() ? c.in_flag.get<std::string>() : c.in_flag.dump();
    EXPECT_EQ(resolved({c.command, "--print-config", "--config", file}, c.key), c.in_file);
    EXPECT_EQ(resolved({c.command, "--print-config", "--config", file, "--set", set}, c.key), c.in_set);
    // The flag wins over --set before or after it.
    EXPECT_EQ(resolved({c.command, "--print-config", "--config", file, "--set", set, c.flag, flag_value}, c.key),
              c.in_flag);
    EXPECT_EQ(resolved({c.command, "--print-config", c.flag, flag_value, "--set", set, "--config", file}, c.key),
              c.in_flag);
  }
}

// A flag's value is checked by its key's declaration and names the flag.
TEST(ConfigPrecedence, AFlagsBadValueNamesTheFlagAndKey) {
  for (const auto& [command, flag] : std::vector<std::pair<std::string, std::string>>{
           {"generate", "--seed"}, {"synth", "--seed"}, {"train", "--seed"}, {"frames", "--overlap"}}) {
    const test::CommandResult r = test::run_nsgraph({command, "--print-config", flag, "bogus"});
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.err;
    EXPECT_NE(r.err.find(flag), std::string::npos) << command << ": " << r.err;
  }
}

}  // namespace
}  // namespace nsg
