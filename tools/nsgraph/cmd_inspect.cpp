// `nsgraph inspect <what>`: debugging views of the inputs (docs/architecture.md).
#include "commands.h"

namespace nsg::cli {

void add_inspect_command(CLI::App& root, Context& ctx) {
  CLI::App* inspect = root.add_subcommand("inspect", "Print what the toolkit reads from a release (JSON)");
  inspect->require_subcommand(1);
  add_inspect_centerlines(*inspect, ctx);
  add_inspect_sweep(*inspect, ctx);
  add_inspect_graph(*inspect, ctx);
  add_inspect_layers(*inspect, ctx);
  add_inspect_scenes(*inspect, ctx);
}

}  // namespace nsg::cli
