#include "nsg/nuscenes/lidar.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "nsg/core/error.h"
#include "nsg/nuscenes/database.h"

namespace nsg::nuscenes {

static_assert(std::endian::native == std::endian::little, "the .pcd.bin reader assumes a little-endian host");

namespace {

// Finite check on the raw bits of float32 values: a value is Inf or NaN iff its bits
// without the sign are ≥ those of +Inf, so the largest of them decides (an and and a max
// per vector: an AVX2 clone where the CPU has it).
__attribute__((target_clones("avx2", "default"))) bool all_finite(const uint32_t* words, size_t count) {
  uint32_t largest = 0;
  for (size_t i = 0; i < count; ++i) largest = std::max(largest, words[i] & 0x7fffffffu);
  return largest < 0x7f800000u;
}

}  // namespace

LidarFile::LidarFile(const std::filesystem::path& file) : file_(file) {
  fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    // Missing sweeps usually mean an archive of the release was not extracted (devkit #756).
    const int err = errno;
    throw IoError(file.string(), "",
                  std::string("cannot open LiDAR sweep: ") + std::strerror(err) +
                      (err == ENOENT ? " (was every archive of the release extracted into the dataroot?)" : ""));
  }
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw IoError(file.string(), "", "a regular LiDAR sweep file");
  }
  const size_t bytes = static_cast<size_t>(st.st_size);
  if (bytes % sizeof(LidarPoint) != 0 || bytes / sizeof(LidarPoint) > kMaxRows) {
    ::close(fd_);
    throw ParseError(file.string(), "size " + std::to_string(bytes) + " bytes",
                     bytes % sizeof(LidarPoint) != 0
                         ? "a multiple of 20 bytes (5 float32 per point); the last point is truncated "
                           "(download damage, devkit #233: fetch the file again)"
                         : "at most 2^31 - 1 points (point indices are int32)");
  }
  rows_ = bytes / sizeof(LidarPoint);
}

LidarFile::~LidarFile() { ::close(fd_); }

void LidarFile::fail_not_finite(size_t row) const {
  throw ParseError(file_.string(), "point " + std::to_string(row), "finite x, y, z, intensity, ring");
}

size_t LidarFile::read(std::vector<LidarPoint>& points, size_t max_rows, Check check) {
  const size_t first = next_row_;
  const size_t count = std::min(max_rows, rows_ - next_row_);
  points.resize(count);
  char* out = reinterpret_cast<char*>(points.data());
  const size_t bytes = count * sizeof(LidarPoint);
  size_t done = 0;
  while (done < bytes) {  // one read in practice; loop for short reads
    const ssize_t n = ::read(fd_, out + done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw IoError(file_.string(), "", std::string("read error: ") + (n < 0 ? std::strerror(errno) : "file shrank"));
    done += static_cast<size_t>(n);
  }
  next_row_ += count;
  // The slow scan for the index runs only when a value is bad.
  if (check == Check::kCallerChecks ||
      all_finite(reinterpret_cast<const uint32_t*>(points.data()), count * kLidarPointStrideFloats))
    return first;
  for (size_t i = 0; i < count; ++i) {
    const LidarPoint& p = points[i];
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.intensity) &&
          std::isfinite(p.ring)))
      fail_not_finite(first + i);
  }
  return first;
}

void read_lidar_points(const std::filesystem::path& file, std::vector<LidarPoint>& points) {
  LidarFile f(file);
  f.read(points, f.rows());
}

std::vector<LidarPoint> read_lidar_points(const std::filesystem::path& file) {
  std::vector<LidarPoint> points;
  read_lidar_points(file, points);
  return points;
}

namespace {

geometry::Rigid3 ego_from_sensor(const Database& db, const SampleData& sd) {
  const CalibratedSensor& cs = db.calibrated_sensor[sd.calibrated_sensor];
  return geometry::Rigid3::from_pose(cs.translation, cs.rotation);
}

geometry::Rigid3 global_from_ego(const Database& db, const SampleData& sd) {
  const EgoPose& ep = db.ego_pose[sd.ego_pose];
  return geometry::Rigid3::from_pose(ep.translation, ep.rotation);
}

}  // namespace

geometry::Rigid3 global_from_sensor(const Database& db, Index sample_data_index) {
  const SampleData& sd = db.sample_data[sample_data_index];
  return global_from_ego(db, sd) * ego_from_sensor(db, sd);
}

void sensor_to_global(const Database& db, Index sample_data_index, std::vector<LidarPoint>& points) {
  const SampleData& sd = db.sample_data[sample_data_index];
  float* xyz = reinterpret_cast<float*>(points.data());
  geometry::transform_points_devkit(ego_from_sensor(db, sd), xyz, points.size(), kLidarPointStrideFloats);
  geometry::transform_points_devkit(global_from_ego(db, sd), xyz, points.size(), kLidarPointStrideFloats);
}

std::vector<LidarPoint> load_sweep_global(const Database& db, Index sample_data_index) {
  const SampleData& sd = db.sample_data[sample_data_index];
  if (sd.modality != Modality::kLidar) {
    throw DataError(db.sample_data.file(), "token " + sd.token.str(),
                    std::string("a lidar sample_data (this one is ") + modality_name(sd.modality) + ", channel " +
                        db.channel(sd) + ")");
  }
  std::vector<LidarPoint> points = read_lidar_points(db.file_path(sd));
  sensor_to_global(db, sample_data_index, points);
  return points;
}

}  // namespace nsg::nuscenes
