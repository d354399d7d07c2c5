// The floor under generate's camera and LiDAR stages: the same files, read and decoded
// and nothing else, one core. bench/camera.sh divides each stage's rate by these.
//   camera_floor DATAROOT [SCALE_DENOM [PASSES]]
// Key-frame images are DATAROOT/samples/CAM_*/*.jpg (decoded whole with libjpeg-turbo at the
// stage's 1/SCALE), their masks DATAROOT/semantic/CAM_*/<basename>.png decoded as stored
// (libpng), sweeps DATAROOT/{samples,sweeps}/LIDAR_TOP/*.pcd.bin read whole from the page
// cache, each into a buffer of its own (sweeps_per_s) and into one kept buffer
// (sweeps_copy_per_s, the bare copy). One untimed pass warms the cache; the printed figure is the median of PASSES.
// Beside the floor, the LiDAR kernel's own arithmetic (sweep_kernel_us): what
// LidarLayer::add_sweep costs per sweep when reading, page faults and cell writes are
// taken away (below), the least the LiDAR stage adds to the read.
// Prints one JSON object: jpeg_per_s, mask_per_s, images_per_s (JPEG + mask), sweeps_per_s,
// sweep_mb_per_s, sweep_kernel_us and the counts.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "nsg/core/error.h"
#include "nsg/geometry/transform.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nsg/raster/lidar_layer.h"

namespace {

namespace fs = std::filesystem;

// Files under root/<dir matching prefix>/ ending in suffix, sorted (a fixed order).
std::vector<fs::path> list_files(const fs::path& root, const std::string& prefix, const std::string& suffix) {
  std::vector<fs::path> out;
  if (!fs::is_directory(root)) return out;
  for (const auto& dir : fs::directory_iterator(root)) {
    if (!dir.is_directory() || dir.path().filename().string().rfind(prefix, 0) != 0) continue;
    for (const auto& f : fs::directory_iterator(dir.path())) {
      const std::string name = f.path().filename().string();
      if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
        out.push_back(f.path());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Median seconds of `passes` timed runs of `work`, after one untimed run.
double median_seconds(int passes, const std::function<void()>& work) {
  work();
  std::vector<double> s;
  for (int i = 0; i < passes; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    work();
    s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(s.begin(), s.end());
  return s[s.size() / 2];
}

// Reads the whole file into `buffer` with open/fstat/read and returns the byte count.
size_t read_whole(const fs::path& file, std::vector<char>& buffer) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0) {
    if (fd >= 0) ::close(fd);
    throw nsg::IoError(file.string(), "", "a readable sweep");
  }
  buffer.resize(static_cast<size_t>(st.st_size));
  size_t done = 0;
  while (done < buffer.size()) {
    const ssize_t n = ::read(fd, buffer.data() + done, buffer.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  ::close(fd);
  return done;
}

// The LiDAR kernel's arithmetic per sweep (µs, median of `passes`): the finite check, the
// roof/range filter, both devkit transforms, the binning and the screen of
// LidarLayer::add_sweep, on each sweep already in memory and with every cell it reaches
// already allocated and in its block table. An untimed pass adds every sweep at one pose
// (LIDAR_TOP's mounting, one fixed ego pose); the timed passes add them again raised by
// 1 km, so the screen turns every point away (but the few within a rounding margin of a
// cell border, which the exact update finds higher): no cell is written, nothing
// allocated. What is left is work the stage does for every point whatever it holds.
double sweep_kernel_us(const std::vector<fs::path>& sweeps, int passes) {
  using nsg::geometry::Quaternion;
  using nsg::geometry::Rigid3;
  const Rigid3 ego_from_sensor =
      Rigid3::from_pose({0.94, 0.0, 1.84}, Quaternion::from_wxyz({0.7071, 0.0, 0.0, 0.7071}));
  const Rigid3 ground = Rigid3::from_pose({600.0, 1700.0, 0.0}, Quaternion::from_wxyz({0.9659, 0.0, 0.0, 0.2588}));
  Rigid3 raised = ground;
  raised.translation.z() += 1000.0;
  const nsg::raster::LidarOptions options;
  nsg::raster::LidarLayer layer(options.resolution_m);
  std::vector<char> rows;
  const auto add = [&](size_t i, const Rigid3& global_from_ego) {
    layer.add_sweep(reinterpret_cast<const float*>(rows.data()), rows.size() / (5 * sizeof(float)), 0, ego_from_sensor,
                    global_from_ego, options, static_cast<int32_t>(i));
  };
  for (size_t i = 0; i < sweeps.size(); ++i) {
    read_whole(sweeps[i], rows);
    add(i, ground);
  }
  std::vector<double> us;
  for (int p = 0; p < passes; ++p) {
    double s = 0.0;
    for (size_t i = 0; i < sweeps.size(); ++i) {
      read_whole(sweeps[i], rows);  // untimed: the read is the floor's part
      const auto t0 = std::chrono::steady_clock::now();
      add(i, raised);
      s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    us.push_back(1e6 * s / static_cast<double>(sweeps.size()));
  }
  std::sort(us.begin(), us.end());
  return us[us.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: camera_floor DATAROOT [SCALE_DENOM [PASSES]]\n");
    return 2;
  }
  const fs::path root = argv[1];
  const int denom = argc > 2 ? std::atoi(argv[2]) : 2;
  const int passes = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
  if (denom != 1 && denom != 2 && denom != 4) {
    std::fprintf(stderr, "camera_floor: SCALE_DENOM: expected 1, 2 or 4 (got %s)\n", argv[2]);
    return 2;
  }
  try {
    const std::vector<fs::path> jpegs = list_files(root / "samples", "CAM_", ".jpg");
    std::vector<fs::path> masks;
    for (const fs::path& j : jpegs) {
      const fs::path m = root / "semantic" / j.parent_path().filename() / (j.stem().string() + ".png");
      if (fs::exists(m)) masks.push_back(m);
    }
    std::vector<fs::path> sweeps = list_files(root / "samples", "LIDAR_TOP", ".pcd.bin");
    const std::vector<fs::path> more = list_files(root / "sweeps", "LIDAR_TOP", ".pcd.bin");
    sweeps.insert(sweeps.end(), more.begin(), more.end());
    if (jpegs.empty()) throw nsg::IoError((root / "samples").string(), "", "key-frame images in samples/CAM_*/");

    nsg::nuscenes::JpegDecoder decoder;
    nsg::nuscenes::RgbImage img;
    size_t sink = 0;
    const double jpeg_s = median_seconds(passes, [&] {
      for (const fs::path& f : jpegs) {
        decoder.decode_file(f, static_cast<nsg::nuscenes::JpegScale>(denom), img);
        sink += img.pixels[0];
      }
    });
    int mask_w = 0;
    nsg::nuscenes::GrayImage m;  // kept, as the image is (and as the stage keeps both)
    const double mask_s = masks.empty() ? 0.0 : median_seconds(passes, [&] {
      for (const fs::path& f : masks) {
        nsg::nuscenes::read_semantic_mask(f, m);
        mask_w = m.width;
        sink += m.pixels[0];
      }
    });
    // Sweeps, two ways. The floor: each file read whole into a buffer of its own (what a
    // reader of whole files does, numpy's fromfile as the devkit reads them: the pages of a
    // fresh buffer are faulted in as the copy fills them). The copy bound, reported beside
    // it: the same reads into one buffer kept between files, so only the copy out of the
    // page cache is left (the stage reads into a kept buffer, in L2-sized runs).
    size_t sweep_bytes = 0;
    const double sweep_s = sweeps.empty() ? 0.0 : median_seconds(passes, [&] {
      sweep_bytes = 0;
      for (const fs::path& f : sweeps) {
        std::vector<char> own;
        sweep_bytes += read_whole(f, own);
        sink += static_cast<size_t>(own.empty() ? 0 : own[0]);
      }
    });
    std::vector<char> kept;
    const double copy_s = sweeps.empty() ? 0.0 : median_seconds(passes, [&] {
      for (const fs::path& f : sweeps) sink += read_whole(f, kept);
    });
    const double kernel_us = sweeps.empty() ? 0.0 : sweep_kernel_us(sweeps, passes);
    const double n = static_cast<double>(jpegs.size());
    std::printf(
        "{\"images\": %zu, \"masks\": %zu, \"mask_width_px\": %d, \"sweeps\": %zu, \"scale_denom\": %d, \"passes\": "
        "%d,\n"
        " \"jpeg_ms\": %.3f, \"mask_ms\": %.3f, \"jpeg_per_s\": %.1f, \"mask_per_s\": %.1f,\n"
        " \"images_per_s\": %.1f, \"sweeps_per_s\": %.1f, \"sweep_mb_per_s\": %.1f, \"sweeps_copy_per_s\": %.1f,"
        " \"sweep_kernel_us\": %.1f, \"sink\": %zu}\n",
        jpegs.size(), masks.size(), mask_w, sweeps.size(), denom, passes, 1e3 * jpeg_s / n,
        masks.empty() ? 0.0 : 1e3 * mask_s / static_cast<double>(masks.size()), n / jpeg_s,
        masks.empty() ? 0.0 : static_cast<double>(masks.size()) / mask_s,
        masks.size() == jpegs.size() ? n / (jpeg_s + mask_s) : 0.0,
        sweeps.empty() ? 0.0 : static_cast<double>(sweeps.size()) / sweep_s,
        sweeps.empty() ? 0.0 : static_cast<double>(sweep_bytes) / 1e6 / sweep_s,
        sweeps.empty() ? 0.0 : static_cast<double>(sweeps.size()) / copy_s, kernel_us, sink % 2);
  } catch (const nsg::Error& e) {
    std::fprintf(stderr, "camera_floor: %s\n", e.what());
    return 2;
  }
  return 0;
}
