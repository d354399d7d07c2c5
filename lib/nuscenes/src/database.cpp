#include "nsg/nuscenes/database.h"

#include <algorithm>
#include <array>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/core/files.h"

namespace nsg::nuscenes {

namespace {

constexpr std::array<const char*, 13> kTableNames = {
    "category", "attribute", "visibility",        "instance",    "sensor", "calibrated_sensor", "ego_pose", "log",
    "scene",    "sample",    "sample_annotation", "sample_data", "map"};

std::string record_of(const Token& token) { return "token " + token.str(); }

// Resolves one link of `row` (a record of `from`) into `to`; a non-empty token that is not
// found is a DataError naming the file, the record and the field.
template <class From, class To>
Index link(const Table<From>& from, const From& row, const char* field, const Token& token, const Table<To>& to,
           bool required) {
  if (token.empty()) {
    if (required)
      throw DataError(from.file(), record_of(row.token),
                      std::string("field \"") + field + "\": a non-empty " + table_name<To>() + " token");
    return kNoIndex;
  }
  const Index i = to.find(token);
  if (i == kNoIndex) {
    throw DataError(from.file(), record_of(row.token),
                    std::string("field \"") + field + "\": " + table_name<To>() + " token " + token.str() +
                        " does not exist in " + to.file());
  }
  return i;
}

// Release folders under `dataroot`: sub-folders holding a category.json, sorted.
std::vector<std::string> version_folders(const std::filesystem::path& dataroot) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dataroot, ec)) {
    std::error_code ec2;
    if (entry.is_directory(ec2) && std::filesystem::is_regular_file(entry.path() / "category.json", ec2))
      out.push_back(entry.path().filename().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// --version defaults to v1.0-trainval, so a dataroot holding only v1.0-mini/ is common:
// name the release folders that do exist instead of "missing category table".
void require_version_folder(const std::filesystem::path& dataroot, const std::string& version) {
  std::error_code ec;
  if (std::filesystem::is_directory(dataroot / version, ec)) return;
  const std::vector<std::string> found = version_folders(dataroot);
  std::string what = "no " + version + "/ under " + dataroot.string();
  if (found.empty()) {
    what += "; found no release folder (a folder holding category.json) there either";
  } else {
    std::string list;
    for (const std::string& f : found) {
      if (!list.empty()) list += ", ";
      list += f;
    }
    what += "; found: " + list +
            (found.size() == 1 ? " (use --version " + found.front() + ")" : " (pick one with --version)");
  }
  throw IoError((dataroot / version).string(), "", what);
}

}  // namespace

// The devkit asserts that every category has an "index" once lidarseg.json (or
// panoptic.json) is present: the nuScenes-lidarseg category.json must be used with it.
void Database::check_lidarseg_categories() const {
  std::error_code ec;
  const char* task = std::filesystem::exists(table_path("lidarseg"), ec)   ? "lidarseg.json"
                     : std::filesystem::exists(table_path("panoptic"), ec) ? "panoptic.json"
                                                                           : nullptr;
  if (task == nullptr) return;
  for (const Category& c : category) {
    if (!c.index) {
      throw DataError(category.file(), record_of(c.token) + " (" + c.name + ")",
                      std::string("an \"index\" in every category record: ") + task +
                          " exists, so (like the devkit) the nuScenes-lidarseg category.json is required");
    }
  }
}

std::filesystem::path Database::table_path(std::string_view table) const {
  return dataroot_ / version_ / (std::string(table) + ".json");
}

Database Database::load(const std::filesystem::path& dataroot, const std::string& version, const LoadOptions& options) {
  options.validate();
  if (version.empty() || version.find('/') != std::string::npos || version == "." || version == "..") {
    throw ConfigError("", version, "a release version folder name such as \"v1.0-mini\"");
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(dataroot, ec)) {
    throw IoError(dataroot.string(), "", "a dataroot folder (missing or not a directory)");
  }
  Database db;
  db.dataroot_ = dataroot;
  db.version_ = version;
  require_version_folder(dataroot, version);
  // The devkit fails early if any table is missing; so do we, before parsing anything.
  for (const char* name : kTableNames) require_file(db.table_path(name), std::string(name) + " table");

  db.category = Table<Category>::load(db.table_path("category"));
  db.check_lidarseg_categories();
  db.attribute = Table<Attribute>::load(db.table_path("attribute"));
  db.visibility = Table<Visibility>::load(db.table_path("visibility"));
  db.instance = Table<Instance>::load(db.table_path("instance"));
  db.sensor = Table<Sensor>::load(db.table_path("sensor"));
  db.calibrated_sensor = Table<CalibratedSensor>::load(db.table_path("calibrated_sensor"));
  db.ego_pose = Table<EgoPose>::load(db.table_path("ego_pose"));
  db.log = Table<Log>::load(db.table_path("log"));
  db.scene = Table<Scene>::load(db.table_path("scene"));
  db.sample = Table<Sample>::load(db.table_path("sample"));
  db.sample_data = Table<SampleData>::load(db.table_path("sample_data"));
  db.sample_annotation = Table<SampleAnnotation>::load(db.table_path("sample_annotation"));
  db.map = Table<Map>::load(db.table_path("map"));

  db.resolve_links();
  db.check_maps(options);
  db.derive_indices();
  return db;
}

void Database::resolve_links() {
  for (CalibratedSensor& r : calibrated_sensor.rows()) {
    r.sensor = link(calibrated_sensor, r, "sensor_token", r.sensor_token, sensor, true);
  }
  for (Instance& r : instance.rows()) {
    r.category = link(instance, r, "category_token", r.category_token, category, true);
    r.first_annotation = link(instance, r, "first_annotation_token", r.first_annotation_token, sample_annotation, true);
    r.last_annotation = link(instance, r, "last_annotation_token", r.last_annotation_token, sample_annotation, true);
  }
  for (Scene& r : scene.rows()) {
    r.log = link(scene, r, "log_token", r.log_token, log, true);
    r.first_sample = link(scene, r, "first_sample_token", r.first_sample_token, sample, true);
    r.last_sample = link(scene, r, "last_sample_token", r.last_sample_token, sample, true);
  }
  for (Sample& r : sample.rows()) {
    r.scene = link(sample, r, "scene_token", r.scene_token, scene, true);
    r.prev = link(sample, r, "prev", r.prev_token, sample, false);
    r.next = link(sample, r, "next", r.next_token, sample, false);
  }
  for (SampleData& r : sample_data.rows()) {
    r.sample = link(sample_data, r, "sample_token", r.sample_token, sample, true);
    r.ego_pose = link(sample_data, r, "ego_pose_token", r.ego_pose_token, ego_pose, true);
    r.calibrated_sensor =
        link(sample_data, r, "calibrated_sensor_token", r.calibrated_sensor_token, calibrated_sensor, true);
    r.prev = link(sample_data, r, "prev", r.prev_token, sample_data, false);
    r.next = link(sample_data, r, "next", r.next_token, sample_data, false);
  }
  for (SampleAnnotation& r : sample_annotation.rows()) {
    r.sample = link(sample_annotation, r, "sample_token", r.sample_token, sample, true);
    r.instance = link(sample_annotation, r, "instance_token", r.instance_token, instance, true);
    r.visibility = link(sample_annotation, r, "visibility_token", r.visibility_token, visibility, false);
    r.attributes.clear();
    for (const Token& t : r.attribute_tokens) {
      r.attributes.push_back(link(sample_annotation, r, "attribute_tokens", t, attribute, true));
    }
    r.prev = link(sample_annotation, r, "prev", r.prev_token, sample_annotation, false);
    r.next = link(sample_annotation, r, "next", r.next_token, sample_annotation, false);
  }
  for (Map& r : map.rows()) {
    r.logs.clear();
    for (const Token& t : r.log_tokens) r.logs.push_back(link(map, r, "log_tokens", t, log, true));
  }
}

void Database::check_maps(const LoadOptions& options) {
  // Like the devkit, a log listed by several maps takes the last one.
  for (size_t m = 0; m < map.size(); ++m) {
    for (Index l : map.rows()[m].logs) log.rows()[static_cast<size_t>(l)].map = static_cast<Index>(m);
  }
  for (const Log& l : log) {
    if (l.map == kNoIndex) {
      throw DataError(log.file(), record_of(l.token),
                      "the log to be listed in the log_tokens of some record of " + map.file());
    }
  }
  if (!options.check_map_files) return;
  for (const Map& m : map) {
    NSG_CHECK(stays_inside(m.filename), DataError, map.file(), record_of(m.token),
              "a map.filename inside the dataroot, got '" + printable_text(m.filename) + "'");
    const std::filesystem::path png = dataroot_ / m.filename;
    std::error_code ec;
    if (m.filename.empty() || !std::filesystem::is_regular_file(png, ec)) {
      throw IoError(png.string(), map.file() + " " + record_of(m.token),
                    "the semantic prior PNG named by map.filename (missing)");
    }
  }
}

void Database::derive_indices() {
  for (SampleData& r : sample_data.rows()) {
    r.sensor = calibrated_sensor[r.calibrated_sensor].sensor;
    r.modality = sensor[r.sensor].modality;
  }
  for (size_t i = 0; i < sample_data.size(); ++i) {
    const SampleData& sd = sample_data.rows()[i];
    if (!sd.is_key_frame) continue;
    std::vector<SampleDataRef>& data = sample.rows()[static_cast<size_t>(sd.sample)].data;
    for (const SampleDataRef& ref : data) {
      if (ref.sensor == sd.sensor) {
        throw DataError(sample_data.file(), record_of(sd.token),
                        "one key frame of channel " + sensor[sd.sensor].channel + " per sample; sample " +
                            sd.sample_token.str() + " already has " + sample_data[ref.sample_data].token.str());
      }
    }
    data.push_back({sd.sensor, static_cast<Index>(i)});
  }
  for (size_t i = 0; i < sample_annotation.size(); ++i) {
    SampleAnnotation& a = sample_annotation.rows()[i];
    a.category = instance[a.instance].category;
    sample.rows()[static_cast<size_t>(a.sample)].anns.push_back(static_cast<Index>(i));
  }
}

Index Database::sensor_by_channel(std::string_view channel) const {
  for (size_t i = 0; i < sensor.size(); ++i) {
    if (sensor.rows()[i].channel == channel) return static_cast<Index>(i);
  }
  return kNoIndex;
}

Index Database::key_frame(Index sample_index, std::string_view channel) const {
  for (const SampleDataRef& ref : sample[sample_index].data) {
    if (sensor[ref.sensor].channel == channel) return ref.sample_data;
  }
  return kNoIndex;
}

std::filesystem::path Database::file_path(const SampleData& sd) const {
  NSG_CHECK(stays_inside(sd.filename), DataError, sample_data.file(), record_of(sd.token),
            "a sample_data.filename inside the dataroot, got '" + printable_text(sd.filename) + "'");
  return dataroot_ / sd.filename;
}

}  // namespace nsg::nuscenes
