#pragma once
// Typed records of the 13 nuScenes tables (docs/nuscenes-input.md). Fields read from the
// files keep their JSON names; `*_token` fields hold the link as read and the matching
// Index field (no suffix) its row once Database resolved it (kNoIndex for empty links).
// Fields marked "derived" are computed at load like the devkit does; they are not in files.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/token.h"

namespace nsg::nuscenes {

using Vec3 = std::array<double, 3>;
using Matrix3 = std::array<std::array<double, 3>, 3>;  // row-major
using geometry::Quaternion;

enum class Modality : std::uint8_t { kCamera, kLidar, kRadar };
const char* modality_name(Modality m);

struct Category {
  Token token;
  std::string name;  // dotted, e.g. "vehicle.car"
  std::string description;
  std::optional<int> index;  // lidarseg label index (not in every release)
};

struct Attribute {
  Token token;
  std::string name;
  std::string description;
};

struct Visibility {
  Token token;  // "1".."4"
  std::string level;
  std::string description;
};

struct Sensor {
  Token token;
  std::string channel;
  Modality modality = Modality::kLidar;
};

struct CalibratedSensor {
  Token token;
  Token sensor_token;
  Index sensor = kNoIndex;
  Vec3 translation{};                       // sensor origin in the ego frame, m
  Quaternion rotation;                      // sensor → ego
  std::optional<Matrix3> camera_intrinsic;  // cameras only ([] in the file otherwise)
};

struct EgoPose {
  Token token;
  std::int64_t timestamp_us = 0;
  Vec3 translation{};   // ego origin in the global frame, m
  Quaternion rotation;  // ego → global
};

struct Log {
  Token token;
  std::string logfile;
  std::string vehicle;
  std::string date_captured;
  std::string location;
  Index map = kNoIndex;  // derived: the map record listing this log
};

struct Map {
  Token token;
  std::string category;
  std::string filename;  // relative to dataroot, "maps/<token>.png"
  std::vector<Token> log_tokens;
  std::vector<Index> logs;
};

struct Scene {
  Token token;
  Token log_token;
  Index log = kNoIndex;
  std::int32_t nbr_samples = 0;
  Token first_sample_token;
  Index first_sample = kNoIndex;
  Token last_sample_token;
  Index last_sample = kNoIndex;
  std::string name;
  std::string description;
};

// One key-frame sample_data of a sample, by sensor (derived `sample.data`).
struct SampleDataRef {
  Index sensor = kNoIndex;
  Index sample_data = kNoIndex;
};

struct Sample {
  Token token;
  std::int64_t timestamp_us = 0;
  Token prev_token;
  Index prev = kNoIndex;
  Token next_token;
  Index next = kNoIndex;
  Token scene_token;
  Index scene = kNoIndex;
  std::vector<SampleDataRef> data;  // derived, in sample_data file order
  std::vector<Index> anns;          // derived, in sample_annotation file order
};

struct SampleData {
  Token token;
  Token sample_token;
  Index sample = kNoIndex;
  Token ego_pose_token;
  Index ego_pose = kNoIndex;
  Token calibrated_sensor_token;
  Index calibrated_sensor = kNoIndex;
  std::int64_t timestamp_us = 0;
  std::string fileformat;  // "pcd", "jpg"
  bool is_key_frame = false;
  std::int32_t height = 0;
  std::int32_t width = 0;
  std::string filename;  // relative to dataroot
  Token prev_token;
  Index prev = kNoIndex;
  Token next_token;
  Index next = kNoIndex;
  Index sensor = kNoIndex;               // derived (calibrated_sensor.sensor): channel
  Modality modality = Modality::kLidar;  // derived
};

struct SampleAnnotation {
  Token token;
  Token sample_token;
  Index sample = kNoIndex;
  Token instance_token;
  Index instance = kNoIndex;
  Token visibility_token;  // may be empty
  Index visibility = kNoIndex;
  std::vector<Token> attribute_tokens;
  std::vector<Index> attributes;
  Vec3 translation{};   // box centre, global m
  Vec3 size{};          // [width, length, height] m
  Quaternion rotation;  // box → global
  Token prev_token;
  Index prev = kNoIndex;
  Token next_token;
  Index next = kNoIndex;
  std::int32_t num_lidar_pts = 0;
  std::int32_t num_radar_pts = 0;
  Index category = kNoIndex;  // derived (instance.category)
};

struct Instance {
  Token token;
  Token category_token;
  Index category = kNoIndex;
  std::int32_t nbr_annotations = 0;
  Token first_annotation_token;
  Index first_annotation = kNoIndex;
  Token last_annotation_token;
  Index last_annotation = kNoIndex;
};

// The table's file stem ("sample_data") for each record type.
template <class Record>
const char* table_name();

// Reads one table file (a JSON array of objects) with simdjson on-demand: never a whole-file
// DOM, keys in any order, unknown keys ignored. Links are left unresolved (kNoIndex).
// Throws IoError (missing/unreadable) or ParseError naming the file, the record (index and
// token when known) and what was expected: wrong type, missing or repeated key, truncated
// file, NaN/inf, invalid token.
template <class Record>
std::vector<Record> read_table(const std::filesystem::path& file);

// One loaded table: its rows in file order and a token → row index.
template <class Record>
class Table {
 public:
  // read_table + the token index; a repeated record token is a ParseError naming both rows.
  static Table load(const std::filesystem::path& file);

  const std::string& file() const { return file_; }
  size_t size() const { return rows_.size(); }
  bool empty() const { return rows_.empty(); }
  const Record& operator[](Index i) const { return rows_[static_cast<size_t>(i)]; }
  Record& operator[](Index i) { return rows_[static_cast<size_t>(i)]; }
  const std::vector<Record>& rows() const { return rows_; }
  std::vector<Record>& rows() { return rows_; }
  auto begin() const { return rows_.begin(); }
  auto end() const { return rows_.end(); }

  // Row of `token`, kNoIndex if absent (or empty).
  Index find(const Token& token) const;
  // Row of `token`; throws DataError(file, token, "unknown <table> token") if absent.
  const Record& get(const Token& token) const;

 private:
  std::string file_;
  std::vector<Record> rows_;
  TokenIndex index_;
};

}  // namespace nsg::nuscenes
