// The one translation unit that includes PCL (compile time, and PCL's dependency web, stay
// confined here; see lib/pipeline/CMakeLists.txt).
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/pipeline/export_cloud.h"

namespace nsg::pipeline {

namespace {

// Field layout of one point in the blob: x y z intensity rgb (float32 ×5) + label (uint32).
constexpr uint32_t kPointBytes = 24;

pcl::PCLPointField field(const char* name, uint32_t offset, uint8_t datatype) {
  pcl::PCLPointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = datatype;
  f.count = 1;
  return f;
}

pcl::PCLPointCloud2 to_cloud2(const std::vector<CloudPoint>& points) {
  pcl::PCLPointCloud2 cloud;
  cloud.height = 1;
  cloud.width = static_cast<uint32_t>(points.size());
  cloud.is_bigendian = false;
  cloud.is_dense = true;  // every point is finite
  cloud.point_step = kPointBytes;
  cloud.row_step = kPointBytes * cloud.width;
  using F = pcl::PCLPointField;
  // rgb is a float field holding the packed bits, as pcl::PointXYZRGB(L) writes it.
  cloud.fields = {field("x", 0, F::FLOAT32),          field("y", 4, F::FLOAT32),    field("z", 8, F::FLOAT32),
                  field("intensity", 12, F::FLOAT32), field("rgb", 16, F::FLOAT32), field("label", 20, F::UINT32)};
  cloud.data.resize(static_cast<size_t>(cloud.row_step));
  uint8_t* out = cloud.data.data();
  for (const CloudPoint& p : points) {
    const float xyzi[4] = {p.x_m, p.y_m, p.z_m, p.intensity};
    std::memcpy(out, xyzi, sizeof xyzi);
    std::memcpy(out + 16, &p.rgb, 4);
    std::memcpy(out + 20, &p.label, 4);
    out += kPointBytes;
  }
  return cloud;
}

// PCL's writeBinary(PCLPointCloud2) sizes the file for its page-aligned mmap, leaving up
// to a page of zeros after the points; readers that check the size (numpy, pypcd) expect
// header + points exactly, so the temp file is cut there.
void drop_mmap_padding(const std::filesystem::path& temp, size_t data_bytes) {
  std::ifstream in(temp, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  const std::string marker = "\nDATA binary\n";
  const size_t at = head.find(marker);
  std::error_code ec;
  const uintmax_t want = at == std::string::npos ? 0 : at + marker.size() + data_bytes;
  const uintmax_t have = std::filesystem::file_size(temp, ec);
  if (at == std::string::npos || ec || have < want) {
    std::filesystem::remove(temp, ec);
    throw IoError(temp.string(), "DATA binary", "a PCD header followed by the points (as pcl::PCDWriter writes)");
  }
  if (have > want) std::filesystem::resize_file(temp, want);
}

}  // namespace

void write_pcd(const std::vector<CloudPoint>& points, const std::filesystem::path& out, PcdFormat format) {
  const pcl::PCLPointCloud2 cloud = to_cloud2(points);
  std::error_code ec;
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path(), ec);
  // PCL writes ascii and binary only to a named file (binary through mmap), so it writes
  // the temp name and we rename: the target appears whole or not at all.
  const std::filesystem::path temp = temp_path_for(out);
  pcl::PCDWriter writer;
  int rc = 0;
  try {
    switch (format) {
      case PcdFormat::kAscii:
        rc = writer.writeASCII(temp.string(), cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(), 8);
        break;
      case PcdFormat::kBinary: rc = writer.writeBinary(temp.string(), cloud); break;
      case PcdFormat::kBinaryCompressed: rc = writer.writeBinaryCompressed(temp.string(), cloud); break;
    }
  } catch (const std::exception& e) {  // pcl::IOException and boost errors
    std::filesystem::remove(temp, ec);
    throw IoError(out.string(), "", std::string("a writable PCD file (PCL: ") + e.what() + ")");
  }
  if (rc != 0) {
    std::filesystem::remove(temp, ec);
    throw IoError(out.string(), "", "a writable PCD file (pcl::PCDWriter failed)");
  }
  if (format == PcdFormat::kBinary) drop_mmap_padding(temp, cloud.data.size());
  try {
    commit_rename(temp, out);
  } catch (...) {
    std::filesystem::remove(temp, ec);
    throw;
  }
}

}  // namespace nsg::pipeline
