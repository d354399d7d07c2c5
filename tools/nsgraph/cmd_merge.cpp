// `nsgraph merge`: checks the shares of a distributed `generate` run (each wrote its own
// part file) and writes the dataset's manifest.json.
#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/pipeline/generate.h"

namespace nsg::cli {

void add_merge_command(CLI::App& root, Context& ctx) {
  struct MergeCliOptions {
    std::string out;
    bool overwrite = false;
  };
  auto opt = std::make_shared<MergeCliOptions>();
  CLI::App* cmd =
      root.add_subcommand("merge", "Check the shares of a distributed generate run and write manifest.json");
  cmd->add_option("--out", opt->out, "The dataset folder all shares wrote to")->required();
  cmd->add_flag("--overwrite", opt->overwrite,
                "Remove what an older dataset left in the folder (files no share recorded, records of another "
                "share count, another config's manifest.json) instead of refusing");
  cmd->callback([opt, &ctx] {
    ctx.run = [opt] {
      pipeline::merge(opt->out, opt->overwrite);
      log::info("merge: " + opt->out + "/manifest.json written");
      return kExitOk;
    };
  });
}

}  // namespace nsg::cli
