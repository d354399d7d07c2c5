// `nsgraph inspect layers`: a location's BEV layers as GeoTIFFs (one per modality) for a
// look in QGIS, and coverage figures. The layers come from generate's chain
// (pipeline/location_layers.h) for a generate config, so they equal generate's tiles.
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <optional>
#include <iostream>

#include "bbox_arg.h"
#include "commands.h"
#include "config_flags.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/io/raster.h"
#include "nsg/raster/color_layer.h"
#include "nsg/io/tile_members.h"
#include "nsg/nuscenes/database.h"
#include "nsg/pipeline/location_layers.h"
#include "nsg/pipeline/tile_files.h"
#include "nsg/preview/preview.h"
#include "nsg/tiling/tile.h"

namespace nsg::cli {
namespace {

// A window larger than this is refused: a whole city at 0.2 m/px would be gigabytes.
constexpr int64_t kMaxPixels = 400'000'000;

struct InspectLayersOptions {
  std::shared_ptr<ConfigArgs> config = std::make_shared<ConfigArgs>();
  std::string location, out_dir, bbox_text, png;
  int threads = 0;
};

// What a GIS shows of a layer: band names (the member's description), and for the
// semantic layer the preview's palette as a colour table and the class names as items.
io::GeoTiffOptions gis_options(const io::TileMember& m) {
  io::GeoTiffOptions opt;
  opt.nodata = m.nodata;
  if (m.bands == 3) {
    for (const char* c : {"red", "green", "blue"}) opt.band_descriptions.push_back(std::string("camera ") + c);
  } else {
    opt.band_descriptions.push_back(m.name + ": " + m.description);
  }
  if (m.name == "semantic") {
    opt.color_table.assign(256, {0, 0, 0});
    for (int c = 0; c < preview::kSemanticClassCount; ++c) {
      const preview::Rgb rgb = preview::semantic_color(c);
      opt.color_table[c] = {rgb.r, rgb.g, rgb.b};
      opt.band_metadata.emplace_back("CLASS_" + std::to_string(c), preview::semantic_name(c));
    }
    opt.color_table[255] = {preview::kNoData.r, preview::kNoData.g, preview::kNoData.b};
  }
  return opt;
}

// GDAL's sidecar (.aux.xml) with the class names as the band's categories: QGIS's
// "Paletted/Unique values" and gdalinfo label the values with them (TIFF has no tag for it).
std::string category_sidecar() {
  std::string xml = "<PAMDataset>\n  <PAMRasterBand band=\"1\">\n    <CategoryNames>\n";
  for (int c = 0; c < preview::kSemanticClassCount; ++c)
    xml += std::string("      <Category>") + preview::semantic_name(c) + "</Category>\n";
  return xml + "    </CategoryNames>\n  </PAMRasterBand>\n</PAMDataset>\n";
}

void write_tif(const std::string& path, const io::Raster& r, const io::GeoRef& geo, const io::TileMember& m) {
  const std::vector<uint8_t> bytes = io::encode_geotiff(r, geo, gis_options(m));
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  if (m.name == "semantic") write_file_atomic(path + ".aux.xml", category_sidecar());
}

// The LiDAR and RGB panels as one PNG (the picture of the real key frame in docs/real-data.md).
void write_panels(const InspectLayersOptions& o, const std::string& version, const tiling::TileRasters& r, int w, int h,
                  double res, size_t samples) {
  preview::LayerPanelsInput in{w, h, r.lidar, r.rgb,
                               strprintf("%s, %s: %zu sample%s, %.0f x %.0f m at %.1f m/px", o.location.c_str(),
                                         version.c_str(), samples, samples == 1 ? "" : "s", w * res, h * res, res)};
  preview::LayerPanelsOptions options;
  options.resolution_m = res;
  const std::vector<uint8_t> png = preview::encode_png(preview::render_layer_panels(in, options));
  write_file_atomic(o.png, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

int run(const InspectLayersOptions& o) {
  options::Origins origins;
  pipeline::GenerateConfig config = resolve_generate(*o.config, &origins);
  if (!origins.count("version")) config.version = "v1.0-mini";  // inspect's default release
  if (config.dataroot.empty()) throw ConfigError("", "--dataroot", "the nuScenes dataroot");
  raster::resolve_semantic_source(config.raster.camera, config.dataroot, config.version);
  std::optional<std::array<double, 4>> bbox;
  if (!o.bbox_text.empty()) {
    const graph::TileBounds b = parse_bbox(o.bbox_text);
    bbox = std::array<double, 4>{b.x_west_m, b.y_south_m, b.x_east_m, b.y_north_m};
  }
  const nuscenes::Database db = nuscenes::Database::load(config.dataroot, config.version);
  const pipeline::WindowLayers layers =
      pipeline::window_layers(db, config, o.location, bbox, kMaxPixels, "--bbox", o.threads);
  const tiling::TileRasters& r = layers.rasters;
  const tiling::RasterCounts& counts = layers.counts;
  const int64_t c0 = layers.window.col0, r0 = layers.window.row0, c1 = layers.window.col1, r1 = layers.window.row1;
  const int w = static_cast<int>(c1 - c0), h = static_cast<int>(r1 - r0);
  const double res = layers.resolution_m;
  const io::GeoRef geo{o.location, static_cast<double>(c0) * res, static_cast<double>(r1) * res, res};
  const std::string base = o.out_dir + "/" + o.location;
  nlohmann::ordered_json files = nlohmann::ordered_json::array();
  for (const io::TileMember* m : io::raster_members()) {
    write_tif(base + "." + m->file, pipeline::layer_raster(r, *m), geo, *m);
    files.push_back(base + "." + m->file);
  }
  if (!o.png.empty()) write_panels(o, config.version, r, w, h, res, db.sample.size());

  const double px = static_cast<double>(w) * h;
  nlohmann::ordered_json out = {
      {"location", o.location},
      {"bounds_m", {geo.x_west_m, static_cast<double>(r0) * res, static_cast<double>(c1) * res, geo.y_north_m}},
      {"size_px", {w, h}},
      {"sweeps", layers.stats.sweeps},
      {"points_kept", layers.stats.points_kept},
      {"vehicle_boxes", layers.stats.vehicle_boxes},
      {"cells",
       {{"lidar", counts.lidar}, {"rgb", counts.rgb}, {"semantic", counts.semantic}, {"vehicle", counts.vehicle}}},
      {"coverage", {{"lidar", counts.lidar / px}, {"rgb", counts.rgb / px}, {"semantic", counts.semantic / px}}},
      {"lidar_blocks", layers.stats.lidar_blocks},
      {"lidar_layer_bytes", layers.lidar_layer_bytes},
      {"files", files}};
  if (!o.png.empty()) out["files"].push_back(o.png);
  std::cout << out.dump(2) << "\n";
  return kExitOk;
}

}  // namespace

void add_inspect_layers(CLI::App& inspect, Context& ctx) {
  auto o = std::make_shared<InspectLayersOptions>();
  CLI::App* cmd =
      inspect.add_subcommand("layers", "A location's BEV layers as GeoTIFFs for QGIS, with coverage figures");
  // The generate config's flags (and --config, --set): the layers are generate's.
  add_config_options(cmd, o->config, "Generate config JSON (defaults: samples/generate.json)", /*listing=*/false);
  add_generate_flags(cmd, o->config, {"--dataroot", "--version", "--detections", "--no-rgb", "--no-semantic"});
  cmd->add_option("--location", o->location, "boston-seaport, singapore-onenorth, ...")->required();
  cmd->add_option("--out", o->out_dir, "Folder for <location>.<layer>.tif")->required();
  cmd->add_option("--bbox", o->bbox_text, "Only xmin,ymin,xmax,ymax (map metres); default: the covered extent");
  cmd->add_option("--png", o->png, "Also write the LiDAR and RGB layers side by side as this PNG");
  add_threads_option(cmd, o->threads);
  cmd->callback([o, &ctx] { ctx.run = [o] { return run(*o); }; });
}

}  // namespace nsg::cli
