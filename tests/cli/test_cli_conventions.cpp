// docs/cli.md's conventions, checked on every command's --help: the option names that
// mean one thing, the one --threads default, numbers typed as numbers, negated flags
// described as what giving them does.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace nsg {
namespace {

// The names listed under "Subcommands:" in a --help text.
std::vector<std::string> subcommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  std::string line;
  bool in_list = false;
  while (std::getline(in, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (!in_list || line.size() < 3 || line[0] != ' ' || line[2] == ' ') continue;
    names.push_back(line.substr(2, line.find(' ', 2) - 2));
  }
  return names;
}

// Each long option of a --help text with its whole entry (the option line and its
// wrapped description lines).
std::map<std::string, std::string> options_of(const std::string& help) {
  std::map<std::string, std::string> entries;
  std::istringstream in(help);
  std::string line, current;
  while (std::getline(in, line)) {
    const size_t at = line.find_first_not_of(' ');
    if (at == 2 && line[2] == '-') {
      const size_t long_at = line.find("--", 2);
      if (long_at == std::string::npos) {
        current.clear();
        continue;
      }
      current = line.substr(long_at, line.find_first_of(" ,", long_at) - long_at);
      entries[current] = line;
    } else if (at != std::string::npos && at > 2 && !current.empty()) {
      entries[current] += " " + line.substr(at);
    } else {
      current.clear();
    }
  }
  return entries;
}

// Every command path ("score", "inspect graph") with its --help text.
std::map<std::string, std::string> every_help() {
  std::map<std::string, std::string> helps;
  const test::CommandResult root = test::run_nsgraph({"--help"});
  EXPECT_EQ(root.exit_code, 0);
  for (const std::string& command : subcommands(root.out)) {
    const test::CommandResult r = test::run_nsgraph({command, "--help"});
    EXPECT_EQ(r.exit_code, 0) << command;
    helps[command] = r.out;
    for (const std::string& sub : subcommands(r.out)) {
      const test::CommandResult s = test::run_nsgraph({command, sub, "--help"});
      EXPECT_EQ(s.exit_code, 0) << command << " " << sub;
      helps[command + " " + sub] = s.out;
    }
  }
  return helps;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(CliConventions, EveryCommandsOptionsFollowDocsCli) {
  const std::map<std::string, std::string> helps = every_help();
  ASSERT_GE(helps.size(), 20u);  // 14 commands and inspect's six
  // The commands that read a generated dataset name it --dataset.
  const std::set<std::string> read_a_dataset = {"stats", "preview", "validate", "report", "train", "predict", "frames"};
  for (const auto& [command, help] : helps) {
    const std::map<std::string, std::string> options = options_of(help);
    EXPECT_FALSE(options.empty()) << command;
    if (read_a_dataset.count(command)) EXPECT_TRUE(options.count("--dataset")) << command << " has no --dataset";
    for (const auto& [name, entry] : options) {
      const std::string where = command + " " + name + ": " + entry;
      if (name == "--threads") {  // CLI11 shows the default after the type: "INT:INT in [0 - 1024]=0"
        EXPECT_TRUE(contains(entry, "0 = all cores") && contains(entry, "]=0 ")) << where;
        EXPECT_TRUE(contains(entry, "--threads INT")) << where;
      }
      if (name == "--format") EXPECT_TRUE(contains(entry, "prints on stdout")) << where;
      if (name == "--version") EXPECT_TRUE(contains(entry, "elease")) << where;  // a release's version
      // A negated flag says what giving it does (it described the opposite).
      if (name.rfind("--no-", 0) == 0) {
        const bool negative = contains(entry, "false") || contains(entry, "not ") || contains(entry, "Not ") ||
                              contains(entry, "without") || contains(entry, "Without") || contains(entry, "Skip") ||
                              contains(entry, "off") || contains(entry, "No ");
        EXPECT_TRUE(negative) << where;
      }
      // A number is typed as one: TEXT with a numeric default ("TEXT=3600") is a number
      // read as text.
      const size_t text_at = entry.find(" TEXT=");
      if (text_at != std::string::npos) {
        const size_t from = text_at + 6;
        const std::string value = entry.substr(from, entry.find(' ', from) - from);
        const bool numeric = !value.empty() && value.find_first_not_of("0123456789.-+e") == std::string::npos;
        EXPECT_FALSE(numeric) << where;
      }
    }
  }
}

// Figures the docs state about the tool come from the tool: score --help names the metrics
// version its reports carry, and usage.md the number of checks validate --list-checks lists.
TEST(CliConventions, HelpAndUsageFiguresEqualTheCode) {
  const test::CommandResult help = test::run_nsgraph({"score", "--help"});
  const test::CommandResult list = test::run_nsgraph({"validate", "--list-checks"});
  ASSERT_EQ(list.exit_code, 0) << list.err;
  // The version score reports carry: the const of the report schema's metrics_version.
  const nlohmann::json schema =
      nlohmann::json::parse(test::read_text(test::source_dir() / "schemas/v1/score-report.schema.json"));
  const std::string version = schema["properties"]["metrics_version"]["const"].get<std::string>();
  EXPECT_NE(help.out.find("metrics v" + version + ")"), std::string::npos) << help.out;
  size_t checks = 0;
  for (const char c : list.out) checks += c == '\n';
  const std::string usage = test::read_text(test::source_dir() / "docs/usage.md");
  EXPECT_NE(usage.find("and " + std::to_string(checks) + " named checks"), std::string::npos)
      << "docs/usage.md should say validate has " << checks << " named checks";
}

}  // namespace
}  // namespace nsg
