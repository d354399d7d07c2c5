// nsgraph: one binary, one subcommand per pipeline stage (DESIGN.md §2).
#include <cstdio>
#include <exception>
#include <new>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/version.h"

namespace {

// The one explicit command table (no self-registering statics).
constexpr nsg::cli::AddCommand kCommands[] = {
    &nsg::cli::add_synth_command,
    &nsg::cli::add_inspect_command,
    &nsg::cli::add_generate_command,
    &nsg::cli::add_merge_command,
    &nsg::cli::add_stats_command,
    &nsg::cli::add_score_command,
    &nsg::cli::add_preview_command,
    &nsg::cli::add_validate_command,
    &nsg::cli::add_export_cloud_command,
    &nsg::cli::add_train_command,
    &nsg::cli::add_predict_command,
};

int run(int argc, char** argv) {
  CLI::App app{"nsgraph — build, validate and score the NuScenesGraph lane-graph benchmark"};
  app.set_version_flag("--version", std::string("nsgraph ") + nsg::kVersion);
  app.require_subcommand(1);
  app.fallthrough();  // global flags are accepted after the command name too
  nsg::cli::Context ctx;
  app.add_flag("-q,--quiet", ctx.quiet, "Only errors on stderr");
  app.add_flag("-v,--verbose", ctx.verbose, "Debug log lines");
  for (nsg::cli::AddCommand add : kCommands) add(app, ctx);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help/version or the usage error
    return code == 0 ? nsg::kExitOk : nsg::kExitInput;
  }
  if (ctx.quiet) nsg::log::set_level(nsg::log::Level::kError);
  if (ctx.verbose) nsg::log::set_level(nsg::log::Level::kDebug);
  if (!ctx.run) throw nsg::InternalError("", "", "command selected without a runner");
  return ctx.run();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const nsg::Error& e) {
    std::fprintf(stderr, "nsgraph: error: %s\n", e.what());
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "nsgraph: error: out of memory\n");
    return nsg::kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nsgraph: internal error: %s\n", e.what());
    return nsg::kExitInternal;
  }
}
