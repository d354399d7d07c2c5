#include "nsg/nuscenes/lidar.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "nsg/core/error.h"
#include "nsg/nuscenes/database.h"

namespace nsg::nuscenes {

static_assert(std::endian::native == std::endian::little, "the .pcd.bin reader assumes a little-endian host");

namespace {

// Closes the descriptor on every path out of the reader.
struct FileDescriptor {
  int fd = -1;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// Finite check on the raw bits of float32 values (exponent all ones = Inf or NaN),
// branch-free so it vectorizes (an AVX2 clone where the CPU has it).
__attribute__((target_clones("avx2", "default"))) bool all_finite(const uint32_t* words, size_t count) {
  uint32_t any_bad = 0;
  for (size_t i = 0; i < count; ++i) any_bad |= static_cast<uint32_t>((words[i] & 0x7f800000u) == 0x7f800000u);
  return any_bad == 0;
}

}  // namespace

void read_lidar_points(const std::filesystem::path& file, std::vector<LidarPoint>& points) {
  FileDescriptor f;
  f.fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (f.fd < 0) throw IoError(file.string(), "", std::string("cannot open LiDAR sweep: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0 || !S_ISREG(st.st_mode)) throw IoError(file.string(), "", "a regular LiDAR sweep file");
  const size_t bytes = static_cast<size_t>(st.st_size);
  if (bytes % sizeof(LidarPoint) != 0) {
    throw ParseError(file.string(), "size " + std::to_string(bytes) + " bytes",
                     "a multiple of 20 bytes (5 float32 per point); the last point is truncated");
  }
  points.resize(bytes / sizeof(LidarPoint));
  char* out = reinterpret_cast<char*>(points.data());
  size_t done = 0;
  while (done < bytes) {  // one read in practice; loop for short reads
    const ssize_t n = ::read(f.fd, out + done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw IoError(file.string(), "", std::string("read error: ") + (n < 0 ? std::strerror(errno) : "file shrank"));
    done += static_cast<size_t>(n);
  }
  // The slow scan for the index runs only when a value is bad.
  if (all_finite(reinterpret_cast<const uint32_t*>(points.data()), points.size() * kLidarPointStrideFloats)) return;
  for (size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& p = points[i];
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.intensity) &&
          std::isfinite(p.ring))) {
      throw ParseError(file.string(), "point " + std::to_string(i), "finite x, y, z, intensity, ring");
    }
  }
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
