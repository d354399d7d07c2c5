// `nsgraph export-cloud`: one scene's accumulated lowest-z ground cloud (intensity, RGB,
// semantic label) as a PCD file for PCL tools.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <iostream>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/pipeline/export_cloud.h"

namespace nsg::cli {
namespace {

struct ExportCloudCommandOptions {
  pipeline::ExportCloudOptions cloud;
  std::string format = "binary", semantic_root;
  bool no_rgb = false, no_semantic = false;

  pipeline::ExportCloudOptions resolve() const {
    pipeline::ExportCloudOptions o = cloud;
    o.format = pipeline::parse_pcd_format(format);
    if (no_rgb) o.raster.camera.rgb = false;
    if (no_semantic) o.raster.camera.semantic = false;
    if (!semantic_root.empty()) o.raster.camera.semantic_root = semantic_root;
    return o;
  }
};

int run(const ExportCloudCommandOptions& in) {
  const pipeline::ExportCloudOptions o = in.resolve();
  const pipeline::SceneCloud cloud = pipeline::export_cloud(o);
  const nlohmann::ordered_json out = {{"scene", cloud.scene},
                                      {"location", cloud.location},
                                      {"file", o.out.string()},
                                      {"encoding", pipeline::pcd_format_name(o.format)},
                                      {"bytes", std::filesystem::file_size(o.out)},
                                      {"points", cloud.points.size()},
                                      {"sweeps", cloud.sweeps},
                                      {"images", cloud.images},
                                      {"rgb_points", cloud.rgb_points},
                                      {"labelled_points", cloud.labelled_points}};
  std::cout << out.dump(2) << "\n";
  return kExitOk;
}

}  // namespace

void add_export_cloud_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<ExportCloudCommandOptions>();
  CLI::App* cmd =
      root.add_subcommand("export-cloud", "One scene's lowest-z ground cloud (intensity, RGB, label) as PCD");
  cmd->add_option("--dataroot", o->cloud.dataroot, "nuScenes dataroot")->required();
  cmd->add_option("--version", o->cloud.version, "Release version")->capture_default_str();
  cmd->add_option("--scene", o->cloud.scene, "Scene name (scene.json 'name', e.g. scene-0061)")->required();
  cmd->add_option("--out", o->cloud.out, "The .pcd file to write")->required();
  // --encoding, not --format: --format is what a command prints on stdout (docs/cli.md).
  cmd->add_option("--encoding", o->format, "How the PCD file stores points: binary, ascii or binary_compressed")
      ->capture_default_str();
  cmd->add_option("--semantic-root", o->semantic_root, "Semantic masks root (default <dataroot>/semantic)");
  cmd->add_flag("--no-rgb", o->no_rgb, "Skip camera colours (rgb = 0)");
  cmd->add_flag("--no-semantic", o->no_semantic, "Skip semantic masks (label = 255)");
  add_threads_option(cmd, o->cloud.threads);
  cmd->callback([o, &ctx] { ctx.run = [o] { return run(*o); }; });
}

}  // namespace nsg::cli
