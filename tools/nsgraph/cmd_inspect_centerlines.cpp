// `nsgraph inspect centerlines`: every lane / lane-connector centerline as the devkit's
// discretize_lanes gives it, plus the connectivity edges, as JSON on stdout.
#include <iostream>
#include <memory>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/issues.h"
#include "nsg/core/log.h"
#include "nsg/geometry/georef.h"
#include "nsg/nuscenes/map_expansion.h"

namespace nsg::cli {
namespace {

struct InspectCenterlinesOptions {
  std::string dataroot;
  std::string location;
  nuscenes::CenterlinesJsonOptions json;

  void validate() const {
    NSG_CHECK(!dataroot.empty(), ConfigError, "", "--dataroot", "expected a dataset root folder");
    (void)geometry::location_info(location);  // ConfigError unless one of the four names
    json.validate();
  }
};

int run_inspect_centerlines(const InspectCenterlinesOptions& options) {
  options.validate();
  const nuscenes::MapExpansion map = nuscenes::load_map_expansion(options.dataroot, options.location);
  std::ios::sync_with_stdio(false);  // large outputs: let cout buffer
  Issues defects = map.issues();
  nuscenes::write_centerlines_json(map, options.json, std::cout, &defects);
  std::cout.flush();
  if (!std::cout) throw IoError("<stdout>", "", "write failed");
  // Map defects the devkit tolerates go to stderr: stdout stays the centerline JSON.
  for (const Issue& issue : defects.items()) {
    log::warn(std::string(severity_name(issue.severity)) + " " + issue.check + " " + issue.subject + ": " +
              issue.message);
  }
  return kExitOk;
}

}  // namespace

void add_inspect_centerlines(CLI::App& parent, Context& ctx) {
  auto options = std::make_shared<InspectCenterlinesOptions>();
  CLI::App* cmd = parent.add_subcommand(
      "centerlines",
      "Print lane and lane-connector centerlines (devkit discretize_lanes) and connectivity edges as JSON");
  cmd->add_option("--dataroot", options->dataroot, "nuScenes dataset root (holds maps/expansion/)")->required();
  cmd->add_option("--location", options->location,
                  "boston-seaport, singapore-onenorth, singapore-hollandvillage or singapore-queenstown")
      ->required();
  cmd->add_option("--resolution", options->json.resolution_m,
                  "Discretization resolution in metres (devkit resolution_meters)")
      ->capture_default_str();
  cmd->add_option("--tokens", options->json.tokens,
                  "Only these lane / lane-connector tokens, comma-separated (edges: only from them)")
      ->delimiter(',');
  cmd->callback([options, &ctx] { ctx.run = [options] { return run_inspect_centerlines(*options); }; });
}

}  // namespace nsg::cli
