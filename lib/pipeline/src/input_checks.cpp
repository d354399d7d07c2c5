#include "nsg/pipeline/input_checks.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/raster/color_layer.h"

namespace nsg::pipeline {
namespace fs = std::filesystem;

namespace {

// Counts the files of one kind and remembers the first missing one.
struct FileTally {
  FileTally(const char* what_files, const char* why) : what(what_files), hint(why) {}
  const char* what;  // "LiDAR sweeps"
  const char* hint;  // what usually explains a missing one
  size_t files = 0, missing = 0;
  fs::path first_missing;

  void check(const fs::path& file) {
    ++files;
    std::error_code ec;
    if (fs::is_regular_file(file, ec)) return;
    if (missing++ == 0) first_missing = file;
  }
  void throw_if_missing() const {
    if (missing == 0) return;
    throw IoError(
        first_missing.string(), "",
        strprintf("every one of the run's %zu %s (%zu missing, this one first); %s", files, what, missing, hint));
  }
};

}  // namespace

std::string InputCounts::describe() const {
  return strprintf("%zu scene(s), %zu map expansion(s), %zu sweep(s), %zu camera image(s), %zu mask(s)", scenes, maps,
                   sweeps, images, masks);
}

InputCounts check_run_inputs(const nuscenes::Database& db, const GenerateConfig& config,
                             const std::vector<std::string>& locations, const std::vector<char>& excluded) {
  const std::set<std::string> wanted(locations.begin(), locations.end());
  const raster::CameraOptions& camera = config.raster.camera;
  const bool images = camera.rgb || camera.semantic;
  InputCounts counts;
  FileTally maps{"map expansions", "the map expansion (nuScenes-map-expansion-v1.3) is extracted into <dataroot>/maps"};
  for (const std::string& location : locations)
    maps.check(fs::path(config.dataroot) / "maps" / "expansion" / (location + ".json"));
  std::vector<char> in_run(db.scene.size(), 0);
  for (nuscenes::Index s = 0; s < static_cast<nuscenes::Index>(db.scene.size()); ++s) {
    const nuscenes::Scene& scene = db.scene[s];
    if (excluded[static_cast<size_t>(s)] || scene.log == nuscenes::kNoIndex) continue;
    if (!wanted.count(db.log[scene.log].location)) continue;
    in_run[static_cast<size_t>(s)] = 1;
    ++counts.scenes;
  }
  FileTally sweeps{"LiDAR sweeps", "was every archive of the release (the sweeps too) extracted into the dataroot?"};
  FileTally pictures{"key-frame camera images", "was every archive of the release extracted into the dataroot?"};
  FileTally masks{"semantic masks (<semantic_root>/<CHANNEL>/<image basename>.png)",
                  "set camera.semantic_root, make them with `nsgraph segment`, or use camera.semantic_source=auto "
                  "or --no-semantic"};
  for (const nuscenes::SampleData& sd : db.sample_data) {
    if (sd.sample == nuscenes::kNoIndex) continue;
    const nuscenes::Index scene = db.sample[sd.sample].scene;
    if (scene == nuscenes::kNoIndex || !in_run[static_cast<size_t>(scene)]) continue;
    if (sd.modality == nuscenes::Modality::kLidar && db.channel(sd) == config.raster.lidar_channel) {
      sweeps.check(db.dataroot() / sd.filename);
    } else if (images && sd.modality == nuscenes::Modality::kCamera && sd.is_key_frame) {
      pictures.check(db.dataroot() / sd.filename);
      if (camera.semantic_masks()) masks.check(raster::semantic_mask_path(db, sd, camera));
    }
  }
  for (const FileTally* t : {&maps, &sweeps, &pictures, &masks}) t->throw_if_missing();
  counts.maps = maps.files;
  counts.sweeps = sweeps.files;
  counts.images = pictures.files;
  counts.masks = masks.files;
  return counts;
}

}  // namespace nsg::pipeline
