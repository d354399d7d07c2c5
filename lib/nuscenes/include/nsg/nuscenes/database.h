#pragma once
// One nuScenes release (dataroot + version) loaded into typed tables with every link
// resolved to a row index once, and the devkit's load-time requirements checked
// (docs/nuscenes-input.md): all 13 table files exist, every map PNG exists, every log is
// listed by some map record, and every foreign key points to an existing record.
#include <filesystem>
#include <string>
#include <string_view>

#include "nsg/nuscenes/tables.h"

namespace nsg::nuscenes {

struct LoadOptions {
  // The devkit asserts every map.filename PNG exists (its content is read lazily).
  bool check_map_files = true;

  // Throws ConfigError on an invalid combination (none today; kept for symmetry).
  void validate() const {}
};

class Database {
 public:
  // Loads <dataroot>/<version>/*.json. Throws IoError (missing dataroot, table file or map
  // PNG; a missing <version>/ names the release folders that exist), ParseError (malformed
  // table) or DataError (dangling link: names the table file, the record token and the
  // field; log listed by no map; two key frames of one channel in a sample; a category
  // without "index" when lidarseg.json exists, as the devkit asserts). Empty tables (the
  // test split's instance and sample_annotation) load as empty.
  static Database load(const std::filesystem::path& dataroot, const std::string& version,
                       const LoadOptions& options = {});

  const std::filesystem::path& dataroot() const { return dataroot_; }
  const std::string& version() const { return version_; }
  // <dataroot>/<version>/<table>.json
  std::filesystem::path table_path(std::string_view table) const;
  // <dataroot>/<sample_data.filename>. DataError naming the record when the filename is
  // absolute or climbs out of the dataroot ('..'): a table may not make us read elsewhere.
  std::filesystem::path file_path(const SampleData& sd) const;

  // Channel name of a sample_data row (its calibrated sensor's sensor).
  const std::string& channel(const SampleData& sd) const { return sensor[sd.sensor].channel; }
  // Row of the sensor with this channel, kNoIndex if none.
  Index sensor_by_channel(std::string_view channel) const;
  // The sample's key-frame sample_data of `channel` (devkit `sample['data'][channel]`),
  // kNoIndex if the sample has none.
  Index key_frame(Index sample_index, std::string_view channel) const;
  // The map record (semantic prior) of a scene's log.
  Index map_of_scene(Index scene_index) const { return log[scene[scene_index].log].map; }

  // The 13 tables, in the order of the devkit's table_names.
  Table<Category> category;
  Table<Attribute> attribute;
  Table<Visibility> visibility;
  Table<Instance> instance;
  Table<Sensor> sensor;
  Table<CalibratedSensor> calibrated_sensor;
  Table<EgoPose> ego_pose;
  Table<Log> log;
  Table<Scene> scene;
  Table<Sample> sample;
  Table<SampleData> sample_data;
  Table<SampleAnnotation> sample_annotation;
  Table<Map> map;

 private:
  void check_lidarseg_categories() const;
  void resolve_links();
  void derive_indices();
  void check_maps(const LoadOptions& options);

  std::filesystem::path dataroot_;
  std::string version_;
};

}  // namespace nsg::nuscenes
