#pragma once
// Each command adds its CLI11 subcommand to the root app. Parsing fills an options
// struct; the subcommand's callback only stores the runner in the Context, which main()
// calls after parsing (so global flags such as --quiet are applied first). Runners
// validate their options and call a library function: no logic a test would want here.
#include <CLI/CLI.hpp>
#include <functional>

namespace nsg::cli {

struct Context {
  bool quiet = false;
  bool verbose = false;
  std::function<int()> run;  // returns the process exit code
};

using AddCommand = void (*)(CLI::App& root, Context& ctx);

void add_inspect_command(CLI::App& root, Context& ctx);

}  // namespace nsg::cli
