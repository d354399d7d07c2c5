#pragma once
// The hand-built release of tests/data/release (see make_fixture.py there) and helpers
// to copy it and break one file for the malformed-input tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>

#include "nsg/core/error.h"
#include "test_support.h"

namespace nsg::test {

inline std::filesystem::path fixture_root() { return source_dir() / "tests" / "data" / "release"; }
inline const std::string kFixtureVersion = "v1.0-mini";

// Tokens of the fixture (make_fixture.py).
inline const std::string kLog = "10a00000000000000000000000000001";
inline const std::string kScene = "5ce00000000000000000000000000001";
inline const std::string kSample1 = "5a000000000000000000000000000001";
inline const std::string kSample2 = "5a000000000000000000000000000002";
inline const std::string kCsLidar = "c5000000000000000000000000000001";
inline const std::string kCsCam = "c5000000000000000000000000000002";
inline const std::string kSd1 = "5d000000000000000000000000000001";  // LIDAR_TOP key frame, sample 1
inline const std::string kSd2 = "5d000000000000000000000000000002";  // LIDAR_TOP sweep
inline const std::string kSd3 = "5d000000000000000000000000000003";  // LIDAR_TOP key frame, sample 2
inline const std::string kSd4 = "5d000000000000000000000000000004";  // CAM_FRONT, sample 1
inline const std::string kSd5 = "5d000000000000000000000000000005";  // CAM_FRONT, sample 2
inline const std::string kCar = "ca700000000000000000000000000001";
inline const std::string kPed = "ca700000000000000000000000000002";
inline const std::string kMoving = "a7700000000000000000000000000001";
inline const std::string kInstance = "1a000000000000000000000000000001";
inline const std::string kAnn1 = "a1000000000000000000000000000001";
inline const std::string kAnn2 = "a1000000000000000000000000000002";
inline const std::string kMap = "36092f0b03a857c6a3403e25b4b7aab3";
inline const std::string kLidarSensor = "dc8b396651c05aedbb9cdaae573bb567";
inline const std::string kCamSensor = "725903f5b62f56118f4094b46a4470d8";

// A writable copy of the fixture release.
class FixtureCopy {
 public:
  FixtureCopy() : dir_("nuscenes-fixture") {
    std::filesystem::copy(fixture_root(), dir_.path(), std::filesystem::copy_options::recursive);
  }
  const std::filesystem::path& root() const { return dir_.path(); }
  std::filesystem::path table(const std::string& name) const { return root() / kFixtureVersion / (name + ".json"); }
  // Replaces the first occurrence of `from` in the table file by `to` (must occur).
  void replace_in_table(const std::string& name, const std::string& from, const std::string& to) const {
    std::string text = read_text(table(name));
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from << " not in " << name;
    text.replace(at, from.size(), to);
    write_text(table(name), text);
  }

 private:
  TempDir dir_;
};

// Runs `body`, expects an exception of type E whose file() contains `file_part` and whose
// message contains every string of `message_parts`.
template <class E, class Body>
void expect_error(Body&& body, const std::string& file_part, std::initializer_list<std::string> message_parts) {
  try {
    body();
    ADD_FAILURE() << "no exception; expected one naming " << file_part;
  } catch (const E& e) {
    EXPECT_NE(e.file().find(file_part), std::string::npos) << "file: " << e.file() << "\nmessage: " << e.what();
    for (const std::string& part : message_parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "missing \"" << part << "\" in: " << e.what();
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
  }
}

}  // namespace nsg::test
