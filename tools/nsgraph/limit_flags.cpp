#include "limit_flags.h"

#include "nsg/core/strings.h"

namespace nsg::cli {

namespace {
// JSON values allowed per byte of file: the default 10 M values in 128 MiB.
constexpr double kJsonValuesPerByte = 10'000'000.0 / (128.0 * 1024 * 1024);
// Parsing costs about 50 bytes of memory per value; 4 GiB of text is the most a host
// could mean.
constexpr double kMaxFileMb = 4096;
}  // namespace

void add_submission_limit_flags(CLI::App* cmd, validate::SubmissionLimits& limits) {
  cmd->add_option_function<double>(
         "--max-file-mb",
         [&limits](double mb) {
           limits.max_file_bytes = static_cast<int64_t>(mb * 1024 * 1024);
           limits.max_json_values =
               static_cast<int64_t>(static_cast<double>(limits.max_file_bytes) * kJsonValuesPerByte);
         },
         strprintf(
             "Largest submission file or stream accepted, MiB (default %lld; the JSON value limit scales with it)",
             static_cast<long long>(limits.max_file_bytes >> 20)))
      ->check(CLI::Range(1.0, kMaxFileMb));
}

std::string submission_limits_footer(const validate::SubmissionLimits& limits) {
  return strprintf(
      "Limits (a submission beyond them is refused, exit 1, before scoring): a file or stream (--submission may be a\n"
      "pipe, e.g. /dev/stdin) of at most %lld MiB (--max-file-mb) and %lld JSON values;\n"
      "per tile at most %lld nodes, %lld edges and %.0f px of total edge length, and a shortest-path work (per\n"
      "connected piece: nodes x (nodes + 2 x edges)) of at most %lld, i.e. about 1 800 nodes in one connected piece;\n"
      "node coordinates within +-%.0f px. While a tile is scored, its APLS and TOPO searches against the ground\n"
      "truth may spend at most %lld units of work (about 9 ns each; exit 1 beyond).\n"
      "The per-tile limits bound the scoring time and are the same on every host (docs/scoring-limits.md).\n"
      "Real 256-px tiles hold 100-1500 nodes.",
      static_cast<long long>(limits.max_file_bytes >> 20), static_cast<long long>(limits.max_json_values),
      static_cast<long long>(limits.max_nodes_per_tile), static_cast<long long>(limits.max_edges_per_tile),
      limits.max_edge_length_px_per_tile, static_cast<long long>(limits.max_path_work_per_tile),
      limits.max_abs_coordinate_px, static_cast<long long>(limits.max_search_work_per_tile));
}

}  // namespace nsg::cli
