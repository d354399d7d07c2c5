// `nsgraph stats`: a dataset's key figures per split (labeled area, lane km, vehicle area,
// semantic classes, coverage), as a text table or JSON.
#include <iostream>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/io/stats.h"

namespace nsg::cli {

void add_stats_command(CLI::App& root, Context& ctx) {
  struct StatsOptions {
    std::string dataset;
    bool json = false;
  };
  auto o = std::make_shared<StatsOptions>();
  CLI::App* cmd = root.add_subcommand("stats", "A dataset's key figures per split (the paper's Table I fields)");
  cmd->add_option("dataset,--dataset", o->dataset, "Dataset folder (holds manifest.json)")->required();
  cmd->add_flag("--json", o->json, "JSON instead of a text table");
  cmd->callback([o, &ctx] {
    ctx.run = [o] {
      const io::DatasetStats stats = io::compute_stats(o->dataset, /*progress=*/true);
      if (o->json) std::cout << io::stats_json(stats).dump(2) << "\n";
      else std::cout << io::stats_text(stats);
      return kExitOk;
    };
  });
}

}  // namespace nsg::cli
