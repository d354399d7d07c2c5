// `nsgraph merge`: checks the shares of a distributed `generate` run (each wrote its own
// part file) and writes the dataset's manifest.json.
#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/pipeline/generate.h"

namespace nsg::cli {

void add_merge_command(CLI::App& root, Context& ctx) {
  auto out = std::make_shared<std::string>();
  CLI::App* cmd =
      root.add_subcommand("merge", "Check the shares of a distributed generate run and write manifest.json");
  cmd->add_option("--out", *out, "The dataset folder all shares wrote to")->required();
  cmd->callback([out, &ctx] {
    ctx.run = [out] {
      pipeline::merge(*out);
      log::info("merge: " + *out + "/manifest.json written");
      return kExitOk;
    };
  });
}

}  // namespace nsg::cli
