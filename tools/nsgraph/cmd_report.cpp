// `nsgraph report`: an HTML folder to browse a dataset or a scored submission (lib/report).
// A submission (or baseline) that fails validate's checks exits 1 with the same problem
// list as `score`; unreadable inputs exit 2.
#include <cstdio>
#include <memory>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/report/report.h"

namespace nsg::cli {
namespace {

struct ReportCliOptions {
  std::string dataset;
  std::string leaderboard;  // a folder of score reports
  std::string out;
  report::ReportOptions lib;

  void validate() const {
    NSG_CHECK(dataset.empty() != leaderboard.empty(), ConfigError, "", "--dataset / --leaderboard",
              "one of them: a dataset's report, or a leaderboard of score reports");
    NSG_CHECK(leaderboard.empty() || (lib.submission.empty() && lib.baseline.empty()), ConfigError, "", "--leaderboard",
              "no --submission or --baseline (the reports in the folder are the submissions)");
  }
};

// Exit 0 when every report in the folder is on the page, 1 when some were rejected (the
// page is written without them and lists them), 2 when none is usable.
int run_leaderboard(const ReportCliOptions& o) {
  const report::LeaderboardResult r = report::write_leaderboard(o.leaderboard, o.out);
  // The rejections are the command's result: printed also under --quiet.
  for (const std::string& why : r.rejected)
    std::fputs(("report --leaderboard: rejected " + printable_text(why) + "\n").c_str(), stderr);
  log::info(strprintf("leaderboard: %lld submission(s), %zu rejected, in %s/index.html",
                      static_cast<long long>(r.entries), r.rejected.size(), o.out.c_str()));
  return r.rejected.empty() ? kExitOk : kExitProblems;
}

int run_report(const ReportCliOptions& o) {
  o.validate();
  if (!o.leaderboard.empty()) return run_leaderboard(o);
  const report::ReportResult r = report::write_report(o.dataset, o.out, o.lib);
  if (!r.issues.empty()) {
    std::fputs(r.issues.format().c_str(), stderr);
    log::error(strprintf("%zu problem(s) in submission %s; no report written", r.issues.size(), r.rejected.c_str()));
    return kExitProblems;
  }
  log::info(strprintf("report: %lld tiles, %lld images (%lld reused from the earlier report), %s in %s/index.html",
                      static_cast<long long>(r.tiles), static_cast<long long>(r.images),
                      static_cast<long long>(r.images_reused), human_bytes(static_cast<double>(r.bytes)).c_str(),
                      o.out.c_str()));
  return kExitOk;
}

}  // namespace

void add_report_command(CLI::App& parent, Context& ctx) {
  auto opts = std::make_shared<ReportCliOptions>();
  opts->lib.progress = true;
  CLI::App* cmd = parent.add_subcommand("report", "An HTML report (opens from file://) of a dataset or a submission");
  cmd->add_option("--dataset", opts->dataset, "Dataset folder (manifest.json)");
  cmd->add_option("--leaderboard", opts->leaderboard,
                  "Instead of --dataset: a folder of score reports (nsgraph score --out); writes a sortable page of "
                  "those whose receipts name the same ground truth as the first (exit 1 when some are rejected)");
  cmd->add_option("--out", opts->out, "Report folder (new, empty or an earlier report, which is replaced)")->required();
  cmd->add_option("--submission", opts->lib.submission, "Submission JSON: scores per tile against the dataset");
  cmd->add_option("--baseline", opts->lib.baseline, "A second submission: both scores and their paired difference");
  cmd->add_option("--split", opts->lib.split,
                  "Split to report (default: with a submission the split its keys are tiles of, else all)");
  add_threads_option(cmd, opts->lib.threads);
  cmd->add_option("--schemas", opts->lib.schemas, "Folder of the published schemas (default: installed/source)");
  cmd->callback([opts, &ctx]() { ctx.run = [opts]() { return run_report(*opts); }; });
}

}  // namespace nsg::cli
