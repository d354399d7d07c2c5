#pragma once
// The config keys of the raster stage, declared once (nsg/core/options.h): the LiDAR
// filters (lidar.*), the camera colouring (camera.*) and the vehicle boxes (vehicles.*).
#include "nsg/core/options.h"
#include "nsg/raster/accumulate.h"

namespace nsg::raster {

const options::Table<LidarOptions>& lidar_option_table();
const options::Table<CameraOptions>& camera_option_table();
// lidar.channel, the LiDAR and camera tables, vehicles.*.
const options::Table<RasterOptions>& raster_option_table();

}  // namespace nsg::raster
