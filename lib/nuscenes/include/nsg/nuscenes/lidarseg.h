#pragma once
// nuScenes-lidarseg (docs/nuscenes-input.md): `<version>/lidarseg.json` ({token,
// sample_data_token, filename} per labelled key-frame LIDAR_TOP sweep; the devkit looks a
// record up by the sweep's sample_data token) and `lidarseg/<version>/<sd_token>_lidarseg.bin`,
// one uint8 label per point of the sweep, in the sweep's point order. Labels are the
// `index` of the 32 lidarseg categories (0 noise … 31 vehicle.ego).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "nsg/nuscenes/token.h"

namespace nsg::nuscenes {

class Database;

inline constexpr int kLidarsegClassCount = 32;

// The 32 lidarseg category names by index (the devkit's category.json of nuScenes-lidarseg).
const std::vector<std::string>& lidarseg_class_names();

// The labelled sweeps of a release: per sample_data row, the label file (empty = none).
class LidarsegIndex {
 public:
  // Reads <dataroot>/<version>/lidarseg.json. Throws IoError naming the file when it is
  // missing ("nuScenes-lidarseg is not installed"), ParseError for malformed JSON or a
  // record without token/sample_data_token/filename (naming the record), DataError for a
  // sample_data_token that is no sample_data record or not a LiDAR record.
  static LidarsegIndex load(const Database& db);

  // <dataroot>/<filename> of the sweep's labels; empty path if the sweep has none.
  std::filesystem::path labels_file(Index sample_data) const;
  size_t labelled_sweeps() const { return count_; }

 private:
  std::vector<std::filesystem::path> files_;  // by sample_data row
  size_t count_ = 0;
};

// Reads one `_lidarseg.bin` into `labels` (reused). Throws IoError if unreadable, DataError
// naming the file when its size is not `points` bytes (one label per point of the sweep).
void read_lidarseg_labels(const std::filesystem::path& file, size_t points, std::vector<uint8_t>& labels);

}  // namespace nsg::nuscenes
