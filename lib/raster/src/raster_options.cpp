#include "nsg/raster/raster_options.h"

namespace nsg::raster {

namespace {
// The farthest a LiDAR return or a camera view is taken from: beyond any automotive sensor
// (nuScenes' HDL-32E reaches ~70 m), and what keeps the block map and the views per point
// bounded.
constexpr double kMaxSensorRangeM = 250.0;
}  // namespace

using options::above;
using options::above_up_to;
using options::at_least;
using options::between;
using options::one_of;

const options::Table<LidarOptions>& lidar_option_table() {
  static const options::Table<LidarOptions> table = [] {
    options::Table<LidarOptions> t;
    t.number("lidar.roof_half_size_m", &LidarOptions::roof_half_size_m)
        .unit("m")
        .range(at_least(0))
        .help("Drop points with |x| and |y| below this in the sensor frame (the ego roof, devkit remove_close)");
    t.number("lidar.max_range_m", &LidarOptions::max_range_m)
        .unit("m")
        .range(above_up_to(0, kMaxSensorRangeM))
        .help(
            "Drop points farther than this from the sensor (in its xy plane; at most 250 m, beyond any automotive "
            "LiDAR's reach: the memory plan and the block map scale with its square)");
    return t;
  }();
  return table;
}

const options::Table<CameraOptions>& camera_option_table() {
  static const options::Table<CameraOptions> table = [] {
    options::Table<CameraOptions> t;
    t.boolean("camera.rgb", &CameraOptions::rgb).help("Colour the kept LiDAR points from the key-frame camera images");
    t.boolean("camera.semantic", &CameraOptions::semantic).help("Write the semantic layer");
    t.path("camera.semantic_root", &CameraOptions::semantic_root)
        .help("Folder of the class-id masks, <root>/<CHANNEL>/<image basename>.png (\"\" = <dataroot>/semantic)");
    t.choice(
         "camera.semantic_source", &CameraOptions::semantic_source,
         {{"masks", SemanticSource::kMasks}, {"lidarseg", SemanticSource::kLidarseg}, {"auto", SemanticSource::kAuto}})
        .help(
            "Semantics from the camera images' class-id masks, from nuScenes-lidarseg's point labels (a cell takes "
            "the class of its lowest labelled key-frame point), or auto: masks when the mask folder exists, else "
            "lidarseg when the release has it, else no semantic layer (one notice line); the dataset's manifest "
            "records the source used");
    t.path("camera.lidarseg_labels", &CameraOptions::lidarseg_labels)
        .help(
            "Labels file mapping the lidarseg labels to our classes (\"\" = the built-in "
            "samples/semantic-labels/nuscenes-lidarseg.json)");
    t.number("camera.view_radius_m", &CameraOptions::view_radius_m)
        .unit("m")
        .range(above_up_to(0, kMaxSensorRangeM))
        .help(
            "Key frames whose ego pose is farther than this (in xy) from a point do not colour it (at most 250 m: "
            "the views tried per point grow with its square)");
    t.number("camera.min_depth_m", &CameraOptions::min_depth_m)
        .unit("m")
        .range(at_least(0))
        .help("Views of a point nearer than this to the camera are not used (devkit min_dist)");
    t.integer("camera.occlusion_window_px", &CameraOptions::occlusion_window_px)
        .unit("px")
        .range(between(0, 512))
        .help(
            "How far up the image (full-resolution px) from occlusion_height_m above a point's line of sight a "
            "closer LiDAR return hides it");
    t.integer("camera.occlusion_side_px", &CameraOptions::occlusion_side_px)
        .unit("px")
        .range(between(0, 512))
        .help("How far sideways a closer LiDAR return hides a point (0 = one step between the sweep's columns)");
    t.number("camera.occlusion_height_m", &CameraOptions::occlusion_height_m)
        .unit("m")
        .range(between(0, 10))
        .help("A LiDAR return hides a point only when it stands at least this high above the point's line of sight");
    t.number("camera.occlusion_margin_m", &CameraOptions::occlusion_margin_m)
        .unit("m")
        .range(at_least(0))
        .help("A LiDAR return hides a point only when it is closer to the camera by more than this");
    t.integer("camera.jpeg_scale_denom", &CameraOptions::jpeg_scale_denom)
        .range(one_of({1, 2, 4}))
        .help("Decode the JPEGs at 1/this of their size (turbojpeg scaled decode)");
    return t;
  }();
  return table;
}

const options::Table<RasterOptions>& raster_option_table() {
  static const options::Table<RasterOptions> table = [] {
    options::Table<RasterOptions> t;
    // One channel for the sweeps accumulated and the key-frame sweep of the occlusion test.
    t.text("lidar.channel", &RasterOptions::lidar_channel)
        .non_empty()
        .help("LiDAR channel accumulated and used for the occlusion test (LIDAR_TOP)")
        .then([](RasterOptions& o) { o.camera.lidar_channel = o.lidar_channel; });
    t.include(&RasterOptions::lidar, lidar_option_table());
    t.include(&RasterOptions::camera, camera_option_table());
    t.path("vehicles.detections", &RasterOptions::detections_file)
        .help("nuScenes detection results JSON for the vehicle layer (\"\" = the vehicle.* annotations)");
    t.number("vehicles.score_threshold", &RasterOptions::detection_score_threshold)
        .range(between(0, 1))
        .help("Keep detections with at least this score");
    return t;
  }();
  return table;
}

}  // namespace nsg::raster
