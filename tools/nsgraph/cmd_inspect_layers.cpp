// `nsgraph inspect layers`: a location's BEV layers as GeoTIFFs (one per modality) for a
// look in QGIS, and coverage figures (issue 5).
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <iostream>

#include "bbox_arg.h"
#include "commands.h"
#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/io/raster.h"
#include "nsg/nuscenes/database.h"
#include "nsg/preview/preview.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/tiling/regions.h"
#include "nsg/tiling/tile.h"

namespace nsg::cli {
namespace {

// A window larger than this is refused: a whole city at 0.2 m/px would be gigabytes.
constexpr int64_t kMaxPixels = 400'000'000;

struct InspectLayersOptions {
  std::string dataroot, version = "v1.0-mini", location, out_dir, bbox_text, detections, png;
  bool no_rgb = false, no_semantic = false;
  int threads = 0;
  raster::RasterOptions raster;

  void validate() const {
    raster.validate();
    if (!bbox_text.empty()) parse_bbox(bbox_text);
  }
};

// The window in cells: the bbox, or the extent of the LiDAR cells holding data.
tiling::CellWindow window(const InspectLayersOptions& o, const raster::LidarLayer& lidar) {
  if (o.bbox_text.empty()) {
    const tiling::CellWindow w = tiling::covered_window(lidar);
    if (w.empty()) throw DataError(o.dataroot, "location " + o.location, "LiDAR points at the location");
    return w;
  }
  const graph::TileBounds b = parse_bbox(o.bbox_text);
  const double res = lidar.resolution_m();
  return {static_cast<int64_t>(std::floor(b.x_west_m / res)), static_cast<int64_t>(std::floor(b.y_south_m / res)),
          static_cast<int64_t>(std::ceil(b.x_east_m / res)), static_cast<int64_t>(std::ceil(b.y_north_m / res))};
}

void write_tif(const std::string& path, const io::Raster& r, const io::GeoRef& geo, std::optional<double> nodata) {
  io::GeoTiffOptions opt;
  opt.nodata = nodata;
  const std::vector<uint8_t> bytes = io::encode_geotiff(r, geo, opt);
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

// The LiDAR and RGB panels as one PNG (the README's picture of the real key frame).
void write_panels(const InspectLayersOptions& o, const tiling::TileRasters& r, int w, int h, double res,
                  size_t samples) {
  preview::LayerPanelsInput in{w, h, r.lidar, r.rgb,
                               strprintf("%s, %s: %zu sample%s, %.0f x %.0f m at %.1f m/px", o.location.c_str(),
                                         o.version.c_str(), samples, samples == 1 ? "" : "s", w * res, h * res, res)};
  preview::LayerPanelsOptions options;
  options.resolution_m = res;
  const std::vector<uint8_t> png = preview::encode_png(preview::render_layer_panels(in, options));
  write_file_atomic(o.png, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

int run(const InspectLayersOptions& in) {
  InspectLayersOptions o = in;
  o.raster.detections_file = o.detections;
  if (o.no_rgb) o.raster.camera.rgb = false;
  if (o.no_semantic) o.raster.camera.semantic = false;
  o.validate();
  const nuscenes::Database db = nuscenes::Database::load(o.dataroot, o.version);
  raster::LocationLayers layers = raster::accumulate_location(db, o.location, o.raster, o.threads);
  const tiling::CellWindow win = window(o, layers.lidar);
  const int64_t c0 = win.col0, r0 = win.row0, c1 = win.col1, r1 = win.row1;
  if ((c1 - c0) * (r1 - r0) > kMaxPixels)
    throw ConfigError("", "--bbox", strprintf("a window of at most %lld pixels (this one has %lld; pass a smaller --bbox)",
                                              static_cast<long long>(kMaxPixels),
                                              static_cast<long long>((c1 - c0) * (r1 - r0))));
  raster::ColorLayer color(layers.lidar.resolution_m());
  const bool cameras = o.raster.camera.rgb || o.raster.camera.semantic;
  if (cameras) color = raster::colorize_location(db, o.location, layers.lidar, {{c0, r0, c1, r1}}, o.raster.camera, o.threads);
  const tiling::LocationRasters source{&layers.lidar, cameras ? &color : nullptr, &layers.vehicles, nullptr, nullptr};
  const int w = static_cast<int>(c1 - c0), h = static_cast<int>(r1 - r0);
  tiling::RasterCounts counts;
  const tiling::TileRasters r = tiling::extract_rasters(source, c0, r0, w, h, &counts);

  const double res = layers.lidar.resolution_m();
  const io::GeoRef geo{o.location, static_cast<double>(c0) * res, static_cast<double>(r1) * res, res};
  const auto u8 = [&](const std::vector<uint8_t>& data, int bands) {
    io::Raster x;
    x.width = w;
    x.height = h;
    x.bands = bands;
    x.data = data;
    return x;
  };
  io::Raster vehicle;
  vehicle.width = w;
  vehicle.height = h;
  vehicle.type = io::SampleType::kFloat32;
  vehicle.data.resize(r.vehicle.size() * sizeof(float));
  std::memcpy(vehicle.data.data(), r.vehicle.data(), vehicle.data.size());
  const std::string base = o.out_dir + "/" + o.location;
  write_tif(base + ".lidar.tif", u8(r.lidar, 1), geo, 0.0);
  write_tif(base + ".rgb.tif", u8(r.rgb, 3), geo, 0.0);
  write_tif(base + ".semantic.tif", u8(r.semantic, 1), geo, 255.0);
  write_tif(base + ".vehicle.tif", vehicle, geo, -1.0);
  write_tif(base + ".coverage.tif", u8(r.coverage, 1), geo, std::nullopt);
  if (!o.png.empty()) write_panels(o, r, w, h, res, db.sample.size());

  const double px = static_cast<double>(w) * h;
  nlohmann::ordered_json out = {
      {"location", o.location},
      {"bounds_m", {geo.x_west_m, static_cast<double>(r0) * res, static_cast<double>(c1) * res, geo.y_north_m}},
      {"size_px", {w, h}},
      {"sweeps", layers.stats.sweeps},
      {"points_kept", layers.stats.points_kept},
      {"vehicle_boxes", layers.stats.vehicle_boxes},
      {"cells", {{"lidar", counts.lidar}, {"rgb", counts.rgb}, {"semantic", counts.semantic}, {"vehicle", counts.vehicle}}},
      {"coverage",
       {{"lidar", counts.lidar / px}, {"rgb", counts.rgb / px}, {"semantic", counts.semantic / px}}},
      {"lidar_blocks", layers.stats.lidar_blocks},
      {"lidar_layer_bytes", layers.lidar.cells().memory_bytes()},
      {"files", {base + ".lidar.tif", base + ".rgb.tif", base + ".semantic.tif", base + ".vehicle.tif",
                 base + ".coverage.tif"}}};
  if (!o.png.empty()) out["files"].push_back(o.png);
  std::cout << out.dump(2) << "\n";
  return kExitOk;
}

}  // namespace

void add_inspect_layers(CLI::App& inspect, Context& ctx) {
  auto o = std::make_shared<InspectLayersOptions>();
  CLI::App* cmd = inspect.add_subcommand("layers", "A location's BEV layers as GeoTIFFs for QGIS, with coverage figures");
  cmd->add_option("--dataroot", o->dataroot, "nuScenes dataroot")->required();
  cmd->add_option("--version", o->version, "Release version")->capture_default_str();
  cmd->add_option("--location", o->location, "boston-seaport, singapore-onenorth, ...")->required();
  cmd->add_option("--out", o->out_dir, "Folder for <location>.<layer>.tif")->required();
  cmd->add_option("--bbox", o->bbox_text, "Only xmin,ymin,xmax,ymax (map metres); default: the covered extent");
  cmd->add_option("--detections", o->detections, "Detection results JSON for the vehicle layer");
  cmd->add_option("--png", o->png, "Also write the LiDAR and RGB layers side by side as this PNG");
  cmd->add_flag("--no-rgb", o->no_rgb, "Skip camera colours");
  cmd->add_flag("--no-semantic", o->no_semantic, "Skip semantic masks");
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
  cmd->callback([o, &ctx] { ctx.run = [o] { return run(*o); }; });
}

}  // namespace nsg::cli
