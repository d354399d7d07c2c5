#include "nsg/nuscenes/lidarseg.h"

#include <cerrno>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/core/strings.h"
#include "nsg/core/json.h"
#include "nsg/core/files.h"
#include "nsg/nuscenes/database.h"

namespace nsg::nuscenes {

namespace fs = std::filesystem;

const std::vector<std::string>& lidarseg_class_names() {
  static const std::vector<std::string> names = {
      "noise",
      "animal",
      "human.pedestrian.adult",
      "human.pedestrian.child",
      "human.pedestrian.construction_worker",
      "human.pedestrian.personal_mobility",
      "human.pedestrian.police_officer",
      "human.pedestrian.stroller",
      "human.pedestrian.wheelchair",
      "movable_object.barrier",
      "movable_object.debris",
      "movable_object.pushable_pullable",
      "movable_object.trafficcone",
      "static_object.bicycle_rack",
      "vehicle.bicycle",
      "vehicle.bus.bendy",
      "vehicle.bus.rigid",
      "vehicle.car",
      "vehicle.construction",
      "vehicle.emergency.ambulance",
      "vehicle.emergency.police",
      "vehicle.motorcycle",
      "vehicle.trailer",
      "vehicle.truck",
      "flat.driveable_surface",
      "flat.other",
      "flat.sidewalk",
      "flat.terrain",
      "static.manmade",
      "static.other",
      "static.vegetation",
      "vehicle.ego",
  };
  return names;
}

LidarsegIndex LidarsegIndex::load(const Database& db) {
  const fs::path file = db.table_path("lidarseg");
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw IoError(file.string(), "",
                  "the nuScenes-lidarseg table lidarseg.json (camera.semantic_source \"lidarseg\" needs "
                  "nuScenes-lidarseg extracted into the dataroot)");
  // lidarseg.json is small (one short record per key frame: ~5 MB for trainval).
  const nlohmann::json doc = parse_json_strict(read_file(file), file.string(), "the lidarseg table");
  if (!doc.is_array()) throw ParseError(file.string(), "", "a JSON array of lidarseg records");
  LidarsegIndex index;
  index.files_.resize(db.sample_data.size());
  for (size_t i = 0; i < doc.size(); ++i) {
    const nlohmann::json& r = doc[i];
    const std::string record = "record " + std::to_string(i);
    const auto text = [&](const char* key) {
      if (!r.is_object() || !r.contains(key) || !r[key].is_string())
        throw ParseError(file.string(), record, std::string("a string \"") + key + "\"");
      return r[key].get<std::string>();
    };
    const std::string sd_text = text("sample_data_token"), filename = text("filename");
    if (!stays_inside(filename))
      throw DataError(file.string(), record, "a filename inside the dataroot, got '" + printable_text(filename) + "'");
    text("token");
    const std::optional<Token> sd_token = Token::parse(sd_text);
    const Index sd = sd_token ? db.sample_data.find(*sd_token) : kNoIndex;
    if (sd == kNoIndex)
      throw DataError(file.string(), record + " (sample_data_token " + sd_text + ")",
                      "the token of a sample_data record");
    if (db.sample_data[sd].modality != Modality::kLidar)
      throw DataError(file.string(), record + " (sample_data_token " + sd_text + ")",
                      "a LiDAR sweep (lidarseg labels points of LIDAR_TOP key frames)");
    if (index.files_[static_cast<size_t>(sd)].empty()) ++index.count_;
    index.files_[static_cast<size_t>(sd)] = db.dataroot() / filename;
  }
  return index;
}

fs::path LidarsegIndex::labels_file(Index sample_data) const {
  if (sample_data < 0 || static_cast<size_t>(sample_data) >= files_.size()) return {};
  return files_[static_cast<size_t>(sample_data)];
}

void read_lidarseg_labels(const fs::path& file, size_t points, std::vector<uint8_t>& labels) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(file.string(), "", std::string("cannot open lidarseg labels: ") + std::strerror(errno));
  const auto size = static_cast<size_t>(in.tellg());
  if (size != points)
    throw DataError(file.string(), "",
                    "one uint8 label per point of its sweep (" + std::to_string(points) + " bytes), got " +
                        std::to_string(size) + " bytes");
  labels.resize(size);
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(labels.data()), static_cast<std::streamsize>(size)))
    throw IoError(file.string(), "", "cannot read lidarseg labels");
}

}  // namespace nsg::nuscenes
