// The map readers on good files of every kind and on hostile ones: each refusal is an
// nsg::Error naming the file, before any pixel buffer is allocated from a header's size.
#include <chrono>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <zlib.h>

#include "nsg/core/error.h"
#include "nsg/io/raster.h"
#include "nsg/skeleton/graphify.h"
#include "test_support.h"

namespace {

using nsg::skeleton::read_map_file;

void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string png_bytes(const cv::Mat& m) {
  std::vector<uint8_t> buf;
  cv::imencode(".png", m, buf);
  return std::string(buf.begin(), buf.end());
}

// A .npy (format 1.0) with this header dict and data.
std::string npy_bytes(const std::string& dict, const std::string& data) {
  std::string header = dict;
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out = "\x93NUMPY";
  out += '\x01';
  out += '\x00';
  out += static_cast<char>(header.size() & 0xff);
  out += static_cast<char>(header.size() >> 8);
  return out + header + data;
}

// The error's file and message, for checks that it names the file.
template <typename E, typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.file() + ": " + e.what();
  }
  return "no " + std::string(typeid(E).name()) + " thrown";
}

TEST(MapFiles, ReadsPngTiffAndNpy) {
  nsg::test::TempDir dir("map_files");
  cv::Mat m8(20, 30, CV_8U, cv::Scalar(7)), m16;
  m8.convertTo(m16, CV_16U, 300.0);
  write_bytes(dir / "a.png", png_bytes(m8));
  write_bytes(dir / "b.png", png_bytes(m16));
  EXPECT_EQ(read_map_file(dir / "a.png").type(), CV_8UC1);
  const cv::Mat r16 = read_map_file(dir / "b.png");
  ASSERT_EQ(r16.type(), CV_16UC1);
  EXPECT_EQ(r16.at<uint16_t>(3, 4), 2100);

  nsg::io::Raster r;
  r.width = 30;
  r.height = 20;
  r.type = nsg::io::SampleType::kFloat32;
  r.data.resize(r.expected_bytes());
  const float half = 0.5f;
  std::memcpy(r.data.data(), &half, 4);
  nsg::io::GeoRef geo;
  geo.location = "boston-seaport";
  const auto tif = nsg::io::encode_geotiff(r, geo);
  write_bytes(dir / "c.tif", std::string(tif.begin(), tif.end()));
  const cv::Mat t = read_map_file(dir / "c.tif");
  ASSERT_EQ(t.type(), CV_32FC1);
  EXPECT_EQ(t.size(), cv::Size(30, 20));
  EXPECT_EQ(t.at<float>(0, 0), 0.5f);

  std::string data(20 * 30 * 4, '\0');
  std::memcpy(&data[4 * 31], &half, 4);  // row 1, column 1
  write_bytes(dir / "d.npy", npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (20, 30), }", data));
  const cv::Mat n = read_map_file(dir / "d.npy");
  ASSERT_EQ(n.type(), CV_32FC1);
  EXPECT_EQ(n.size(), cv::Size(30, 20));
  EXPECT_EQ(n.at<float>(1, 1), 0.5f);
  write_bytes(dir / "e.npy",
              npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (20, 30), }", std::string(600, '\x01')));
  EXPECT_EQ(read_map_file(dir / "e.npy").type(), CV_8UC1);
}

TEST(MapFiles, HostileFilesAreRefusedNamingTheFile) {
  nsg::test::TempDir dir("map_files_hostile");
  const std::string png = png_bytes(cv::Mat(64, 64, CV_8U, cv::Scalar(200)));
  write_bytes(dir / "truncated.png", png.substr(0, png.size() / 2));
  std::string huge = png;
  const char big[4] = {0x00, 0x01, static_cast<char>(0x86), static_cast<char>(0xa0)};  // 100000
  std::memcpy(&huge[16], big, 4);
  std::memcpy(&huge[20], big, 4);
  write_bytes(dir / "huge.png", huge);
  write_bytes(dir / "rgb.png", png_bytes(cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3))));
  write_bytes(dir / "i8.npy",
              npy_bytes("{'descr': '<i8', 'fortran_order': False, 'shape': (4, 4), }", std::string(128, '\0')));
  write_bytes(dir / "cube.npy",
              npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 4, 4), }", std::string(128, '\0')));
  write_bytes(dir / "short.npy",
              npy_bytes("{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4), }", std::string(60, '\0')));
  write_bytes(dir / "wide.npy", npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (1, 99999999), }", ""));
  write_bytes(dir / "text.png", "not an image");

  for (const std::string name : {"truncated.png", "text.png", "short.npy"}) {
    const std::string msg = error_of<nsg::ParseError>([&] { read_map_file(dir / name); });
    EXPECT_NE(msg.find(name), std::string::npos) << msg;
  }
  for (const std::string name : {"huge.png", "rgb.png", "i8.npy", "cube.npy", "wide.npy"}) {
    const std::string msg = error_of<nsg::DataError>([&] { read_map_file(dir / name); });
    EXPECT_NE(msg.find(name), std::string::npos) << msg;
  }
  EXPECT_NE(error_of<nsg::DataError>([&] { read_map_file(dir / "huge.png"); }).find("4096"), std::string::npos);
  EXPECT_NE(error_of<nsg::DataError>([&] { read_map_file(dir / "cube.npy"); }).find("2-D"), std::string::npos);
  EXPECT_NE(error_of<nsg::IoError>([&] { read_map_file(dir / "missing.png"); }).find("missing.png"), std::string::npos);
}

// A PNG chunk: length, type, data, CRC.
std::string png_chunk(const std::string& type, const std::string& data) {
  std::string out;
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((data.size() >> shift) & 0xff);
  out += type + data;
  uLong crc = crc32(0, reinterpret_cast<const Bytef*>(type.data()), static_cast<uInt>(type.size()));
  crc = crc32(crc, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size()));
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((crc >> shift) & 0xff);
  return out;
}

// An 8-bit grayscale side x side PNG whose image data is `raw` deflated (as the format
// has it: a filter byte before each row; a well-formed image has side x (side + 1) bytes).
std::string png_with_raw_data(uint32_t side, const std::string& raw, bool interlaced = false) {
  std::string ihdr;
  for (int k = 0; k < 2; ++k)
    for (int shift = 24; shift >= 0; shift -= 8) ihdr += static_cast<char>((side >> shift) & 0xff);
  ihdr += std::string("\x08\x00\x00\x00", 4);  // 8 bit, grayscale, deflate, filter 0
  ihdr += static_cast<char>(interlaced ? 1 : 0);
  uLongf packed_size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(packed_size, '\0');
  compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size, reinterpret_cast<const Bytef*>(raw.data()),
            static_cast<uLong>(raw.size()), 9);
  packed.resize(packed_size);
  return std::string("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + png_chunk("IDAT", packed) +
         png_chunk("IEND", "");
}

// Image data that inflates past the image (a deflate bomb: 1 GiB of it made graphify
// spend minutes and pass) or short of it is refused by its size, before decoding; the
// same construction with the exact size decodes.
TEST(MapFiles, PngImageDataMustInflateToTheImagesSize) {
  nsg::test::TempDir dir("map_files_bomb");
  const uint32_t side = 64;
  write_bytes(dir / "exact.png", png_with_raw_data(side, std::string(side * (side + 1), '\0')));
  const cv::Mat exact = read_map_file(dir / "exact.png");
  EXPECT_EQ(exact.rows, 64);
  EXPECT_EQ(cv::countNonZero(exact), 0);
  write_bytes(dir / "bomb.png", png_with_raw_data(side, std::string(side * (side + 1) + (64u << 20), '\0')));
  const auto start = std::chrono::steady_clock::now();
  const std::string msg = error_of<nsg::ParseError>([&] { read_map_file(dir / "bomb.png"); });
  EXPECT_NE(msg.find("bomb.png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("inflates to more"), std::string::npos) << msg;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0)
      << "the bound stops inflating at the image's size";
  write_bytes(dir / "short.png", png_with_raw_data(side, std::string(side * side, '\0')));
  EXPECT_NE(error_of<nsg::ParseError>([&] { read_map_file(dir / "short.png"); }).find("truncated or corrupt"),
            std::string::npos);
  // Interlaced (Adam7): an 8 x 8 image's seven passes hold 2 + 2 + 3 + 6 + 10 + 20 + 36 = 79
  // bytes (filter bytes included), not 8 x 9 = 72.
  write_bytes(dir / "adam7.png", png_with_raw_data(8, std::string(79, '\0'), true));
  EXPECT_EQ(read_map_file(dir / "adam7.png").rows, 8);
  write_bytes(dir / "adam7-short.png", png_with_raw_data(8, std::string(72, '\0'), true));
  EXPECT_THROW(read_map_file(dir / "adam7-short.png"), nsg::ParseError);
}

TEST(MapFiles, AFolderMapsFileStemsToTileKeys) {
  nsg::test::TempDir dir("map_files_folder");
  cv::Mat mask = cv::Mat::zeros(64, 64, CV_8U);
  mask.rowRange(30, 35).setTo(255);
  write_bytes(dir / "boston-seaport-test-000001.png", png_bytes(mask));
  write_bytes(dir / "boston-seaport-test-000002.png", png_bytes(cv::Mat::zeros(64, 64, CV_8U)));
  write_bytes(dir / "README.txt", "ignored");
  const nsg::metrics::GraphSet set = nsg::skeleton::graphify_input(dir.path(), {});
  ASSERT_EQ(set.size(), 2u);
  EXPECT_FALSE(set.at("boston-seaport-test-000001").edges.empty());
  EXPECT_TRUE(set.at("boston-seaport-test-000002").edges.empty());
  write_bytes(dir / "boston-seaport-test-000001.npy",
              npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 2), }", std::string(4, '\0')));
  EXPECT_THROW(nsg::skeleton::graphify_input(dir.path(), {}), nsg::DataError);
  nsg::test::TempDir empty("map_files_empty");
  EXPECT_THROW(nsg::skeleton::graphify_input(empty.path(), {}), nsg::DataError);
}

}  // namespace
