#pragma once
// Writes a complete synthetic nuScenes-format release (docs/synthetic-release.md): the 13
// tables, map expansion, semantic-prior and basemap PNGs, LiDAR sweeps, camera JPEGs,
// semantic class PNGs and detection results. Byte-identical for a given config and seed,
// whatever the thread count.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/geometry/transform.h"
#include "nsg/synth/config.h"

namespace nsg::synth {

struct SynthRunOptions {
  std::filesystem::path out_dir;  // the dataroot to write (created; existing files replaced)
  int threads = 0;                // 0 = all cores
  bool progress = true;
  void validate() const;  // ConfigError naming the bad field
};

struct SynthSummary {
  int scenes = 0;
  int samples = 0;
  int sample_data = 0;
  int annotations = 0;
  int instances = 0;
  int lanes = 0;
  int lane_connectors = 0;
  uint64_t files = 0;
  uint64_t bytes = 0;
};

SynthSummary write_release(const SynthConfig& config, const SynthRunOptions& options);

// One sensor of the synthetic vehicle: channel, modality, the real sensor token, and the
// calibration (sensor → ego) modelled on the real vehicle's.
struct SensorSpec {
  std::string channel;
  std::string modality;  // camera / lidar / radar
  std::string token;     // the real, fixed sensor token
  std::array<double, 3> translation;
  geometry::Quaternion rotation;
  std::array<double, 4> intrinsic{};  // fx, fy, cx, cy at 1600×900 (cameras only)
};
// All 12 channels in the order of the real sensor table.
const std::vector<SensorSpec>& sensor_specs();

// The semantic-prior map token (= PNG stem) the devkit uses for each location.
std::string semantic_prior_token(const std::string& location);

}  // namespace nsg::synth
