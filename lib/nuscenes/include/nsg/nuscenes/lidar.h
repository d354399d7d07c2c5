#pragma once
// LiDAR sweeps (`.pcd.bin`, docs/nuscenes-input.md) and the sweep → global chain.
#include <cstddef>
#include <filesystem>
#include <vector>

#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/token.h"

namespace nsg::nuscenes {

class Database;

// One point as stored in the file: 5 little-endian float32 (ring stored as float).
struct LidarPoint {
  float x, y, z;
  float intensity;
  float ring;
};
static_assert(sizeof(LidarPoint) == 20, "LidarPoint must match the file record");
inline constexpr size_t kLidarPointStrideFloats = 5;

// A .pcd.bin opened for reading in runs of rows (the sweep loop reads a few thousand rows at
// a time into a small buffer, so it bins each row while the row is still in cache). The
// constructor throws IoError (missing/unreadable) or ParseError (size not a multiple of 20
// bytes, or beyond int32 point indices); read() throws ParseError naming the point when a
// value is not finite — after earlier runs were handed out, so a caller that consumes runs
// as they come must drop what it built from this file on that exception.
class LidarFile {
 public:
  explicit LidarFile(const std::filesystem::path& file);
  ~LidarFile();
  LidarFile(const LidarFile&) = delete;
  LidarFile& operator=(const LidarFile&) = delete;

  size_t rows() const { return rows_; }
  bool done() const { return next_row_ == rows_; }
  // Reads the next min(max_rows, rows left) rows into `points` (resized; capacity kept)
  // and returns the index of the first of them in the file. kCallerChecks skips the
  // finite check: for a caller that checks every value in its own pass over the rows
  // (the sweep kernel) and reports a bad one with fail_not_finite.
  enum class Check { kFinite, kCallerChecks };
  size_t read(std::vector<LidarPoint>& points, size_t max_rows, Check check = Check::kFinite);
  // The ParseError of a value that is not finite in row `row` of the file.
  [[noreturn]] void fail_not_finite(size_t row) const;

  static constexpr size_t kMaxRows = 0x7fffffff;

 private:
  std::filesystem::path file_;
  int fd_ = -1;
  size_t rows_ = 0, next_row_ = 0;
};

// Reads the whole file with a single read into `points` (reused: capacity is kept).
// Throws IoError (missing/unreadable), ParseError if the size is not a multiple of 20
// bytes or a value is not finite (naming the file and the point index).
void read_lidar_points(const std::filesystem::path& file, std::vector<LidarPoint>& points);
std::vector<LidarPoint> read_lidar_points(const std::filesystem::path& file);

// global_from_sensor for one sample_data: its calibrated_sensor (sensor → ego) followed
// by its OWN ego_pose (ego → global).
geometry::Rigid3 global_from_sensor(const Database& db, Index sample_data_index);

// Transforms points (sensor frame) in place to the global frame of `sample_data_index`,
// in two float32 steps like the devkit (sensor → ego, then ego → global).
void sensor_to_global(const Database& db, Index sample_data_index, std::vector<LidarPoint>& points);

// Reads a lidar sample_data's file (dataroot/filename) and returns its points in the
// global frame. Throws DataError if the sample_data is not a lidar record.
std::vector<LidarPoint> load_sweep_global(const Database& db, Index sample_data_index);

}  // namespace nsg::nuscenes
