#pragma once
// Checks shared by the tests of declared configs (generate, synth, train): every key fed
// a bad value through a config file and through --set must be refused by a message that
// names the key and the source it came from; the listing covers the resolved config.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/options.h"
#include "test_support.h"

namespace nsg::test {

// A value the declaration of `spec` refuses (out of range where there is a range, else
// of the wrong type), as JSON text.
inline std::string bad_value(const options::Spec& spec) {
  const options::Range& r = spec.range;
  if (spec.type == "number" || spec.type == "integer") {
    if (!r.only.empty()) return options::OrderedJson(*std::max_element(r.only.begin(), r.only.end()) + 1).dump();
    if (r.min) return options::OrderedJson(*r.min - 1).dump();
    if (r.max) return options::OrderedJson(*r.max + 1).dump();
    return "\"many\"";
  }
  if (spec.type == "boolean") return "\"yes\"";
  if (spec.type == "string") return spec.non_empty ? "\"\"" : "7";
  if (spec.type == "choice") return "\"nowhere\"";
  if (spec.key == "schema_version") return "\"2\"";
  return "7";  // shapes: arrays, objects and checked strings
}

// The message of the ConfigError `resolve` throws ("" if none).
inline std::string config_error(const std::function<void()>& resolve) {
  try {
    resolve();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// `resolve(file, settings)` reads the config the way the command does: the file ("" =
// none), then each --set "key=value". Every key of `specs` is given a bad value both ways.
using ResolveConfig = std::function<void(const std::filesystem::path&, const std::vector<std::string>&)>;
inline void expect_every_key_refused_naming_it(const std::vector<options::Spec>& specs, const ResolveConfig& resolve,
                                               const std::string& name) {
  TempDir dir("config-bad-" + name);
  for (const options::Spec& spec : specs) {
    const std::string bad = bad_value(spec);
    options::OrderedJson doc = options::OrderedJson::object();
    options::insert_at(doc, spec.key, options::OrderedJson::parse(bad));
    const std::filesystem::path file = dir / ("bad-" + spec.key + ".json");
    write_text(file, doc.dump());
    std::string message = config_error([&] { resolve(file, {}); });
    EXPECT_NE(message.find(file.string() + ": " + spec.key), std::string::npos)
        << name << " " << spec.key << " " << bad << ": " << message;
    message = config_error([&] { resolve("", {spec.key + "=" + bad}); });
    EXPECT_NE(message.find("--set: " + spec.key), std::string::npos)
        << name << " " << spec.key << " " << bad << ": " << message;
  }
}

// The keys `nsgraph <command> --list-options --format json` lists, each with a description
// and a type, are exactly the leaves of `nsgraph <command> --print-config` (an object of a
// shape of its own, a listed key, counts as one leaf). Returns the listed keys.
inline std::set<std::string> expect_listed_keys_are_the_config_leaves(const std::string& command) {
  using nlohmann::json;
  const CommandResult list = run_nsgraph({command, "--list-options", "--format", "json"});
  EXPECT_EQ(list.exit_code, 0) << list.err;
  std::set<std::string> listed;
  for (const json& o : json::parse(list.out)) {
    listed.insert(o["key"].get<std::string>());
    EXPECT_FALSE(o["description"].get<std::string>().empty()) << command << " " << o["key"];
    EXPECT_FALSE(o["type"].get<std::string>().empty()) << command << " " << o["key"];
  }
  const CommandResult printed = run_nsgraph({command, "--print-config"});
  EXPECT_EQ(printed.exit_code, 0) << printed.err;
  std::set<std::string> leaves;
  std::function<void(const json&, const std::string&)> walk = [&](const json& node, const std::string& path) {
    if (listed.count(path) || !node.is_object()) {
      leaves.insert(path);
      return;
    }
    for (const auto& [k, v] : node.items()) walk(v, path.empty() ? k : path + "." + k);
  };
  walk(json::parse(printed.out), "");
  EXPECT_EQ(leaves, listed) << command;
  return listed;
}

}  // namespace nsg::test
