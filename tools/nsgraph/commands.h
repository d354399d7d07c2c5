#pragma once
// Each command adds its CLI11 subcommand to the root app. Parsing fills an options
// struct; the subcommand's callback only stores the runner in the Context, which main()
// calls after parsing (so global flags such as --quiet are applied first). Runners
// validate their options and call a library function: no logic a test would want here.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace nsg::cli {

struct Context {
  bool quiet = false;
  bool verbose = false;
  std::function<int()> run;  // returns the process exit code
};

using AddCommand = void (*)(CLI::App& root, Context& ctx);

// Top-level commands (tools/nsgraph/cmd_<name>.cpp), listed in main.cpp's table.
void add_inspect_command(CLI::App& root, Context& ctx);
void add_synth_command(CLI::App& root, Context& ctx);
void add_score_command(CLI::App& root, Context& ctx);
void add_generate_command(CLI::App& root, Context& ctx);
void add_merge_command(CLI::App& root, Context& ctx);
void add_preview_command(CLI::App& root, Context& ctx);
void add_stats_command(CLI::App& root, Context& ctx);
void add_validate_command(CLI::App& root, Context& ctx);
void add_export_cloud_command(CLI::App& root, Context& ctx);
void add_train_command(CLI::App& root, Context& ctx);
void add_predict_command(CLI::App& root, Context& ctx);
void add_segment_command(CLI::App& root, Context& ctx);
void add_report_command(CLI::App& root, Context& ctx);
void add_frames_command(CLI::App& root, Context& ctx);
void add_graphify_command(CLI::App& root, Context& ctx);

// --threads N with the one default (0 = all cores) and range; `what` says what runs in
// parallel ("Worker threads").
CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& what = "Worker threads");

// `inspect` subcommands (cmd_inspect_<what>.cpp), added by add_inspect_command.
void add_inspect_centerlines(CLI::App& inspect, Context& ctx);
void add_inspect_sweep(CLI::App& inspect, Context& ctx);
void add_inspect_graph(CLI::App& inspect, Context& ctx);
void add_inspect_layers(CLI::App& inspect, Context& ctx);
void add_inspect_scenes(CLI::App& inspect, Context& ctx);  // scenes and samples

}  // namespace nsg::cli
