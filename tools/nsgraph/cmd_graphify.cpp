// `nsgraph graphify`: centreline probability maps or binary masks, one per tile (PNG,
// GeoTIFF or .npy), to lane graphs in the submission format (lib/skeleton graphify.h,
// docs/graphify.md): undirected (each edge both ways), or directed by --heading maps.
#include <memory>

#include "commands.h"
#include "config_flags.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/metrics/io.h"
#include "nsg/skeleton/graphify.h"

namespace nsg::cli {
namespace {

struct GraphifyCliOptions {
  std::string input;    // a map file or a folder of <tile key>.<png|tif|tiff|npy>
  std::string out;      // the submission JSON
  std::string heading;  // directed mode: a heading file, or a folder of <tile key>.tif|.tiff|.npy|.vehicle.tif
  std::shared_ptr<ConfigArgs> config = std::make_shared<ConfigArgs>();

  void validate() const {
    NSG_CHECK(!input.empty(), ConfigError, "", "--input", "a map file or a folder of map files");
    NSG_CHECK(!out.empty(), ConfigError, "", "--out", "a submission file to write");
  }
};

int run_graphify(const GraphifyCliOptions& o) {
  if (list_options_if_asked(*o.config, "graphify",
                            "The skeleton rule's options (threshold → thin → trace → prune → anchors), as declared; "
                            "a file may give any subset.",
                            skeleton::graphify_option_table(), skeleton::graphify_config_schema()))
    return kExitOk;
  const skeleton::GraphifyOptions options =
      skeleton::resolve_graphify_config(o.config->config_path, o.config->settings, o.config->flags);
  if (print_config_if_asked(*o.config, skeleton::graphify_option_table(), options)) return kExitOk;
  o.validate();
  const metrics::GraphSet graphs = skeleton::graphify_input(o.input, options, o.heading);
  metrics::write_submission(graphs, o.out);
  size_t nodes = 0, edges = 0;
  for (const auto& [key, g] : graphs) {
    nodes += g.nodes.size();
    edges += g.edges.size();
  }
  log::info(strprintf(
      "graphify: %zu tile(s), %zu nodes, %zu edges (%s) → %s", graphs.size(), nodes, edges,
      o.heading.empty() ? "each undirected edge both ways" : "directed by the headings; both ways where none is known",
      o.out.c_str()));
  return kExitOk;
}

}  // namespace

void add_graphify_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<GraphifyCliOptions>();
  CLI::App* cmd = root.add_subcommand(
      "graphify",
      "Turn per-tile centreline probability maps or masks into a lane-graph submission (undirected, or directed by "
      "--heading)");
  cmd->add_option("--input", o->input,
                  "A map file, or a folder of <tile key>.png|.tif|.tiff|.npy (8/16-bit grayscale PNG, one-band "
                  "uint8/float32 GeoTIFF, 2-D uint8/float32 .npy)");
  cmd->add_option("--out", o->out, "Submission JSON to write (schemas/v1/submission.schema.json)");
  cmd->add_option("--heading", o->heading,
                  "Directed mode: a heading map (float32 GeoTIFF or .npy, fractions of a turn clockwise from north, "
                  "negative = unknown, as the dataset's vehicle layer), or a folder of <tile key>.tif|.tiff|.npy or "
                  "<tile key>.vehicle.tif, one per map");
  add_config_options(cmd, o->config, "Graphify config JSON (any subset of the keys; --list-options)");
  cmd->callback([o, &ctx] { ctx.run = [o] { return run_graphify(*o); }; });
}

}  // namespace nsg::cli
