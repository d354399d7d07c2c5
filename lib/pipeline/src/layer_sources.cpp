#include "layer_sources.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "nsg/core/error.h"
#include "nsg/nuscenes/database.h"

namespace nsg::pipeline {

bool LayerSource::serves(const std::string& split) const {
  return splits.empty() || std::find(splits.begin(), splits.end(), split) != splits.end();
}

std::vector<LayerSource> layer_sources(const nuscenes::Database& db, const GenerateConfig& config,
                                       const std::vector<nuscenes::Index>& scenes) {
  std::vector<LayerSource> out;
  if (config.split_preset == SplitPreset::kRegions) {
    out.emplace_back();
    out.back().name = "all scenes";
    out.back().scenes = scenes;
    return out;
  }
  if (config.split_preset == SplitPreset::kMapUpdate) {  // every split sees the world after the change
    out.emplace_back();
    out.back().name = "from " + config.split_date;
    for (nuscenes::Index s : scenes)
      if (db.log[db.scene[s].log].date_captured >= config.split_date) out.back().scenes.push_back(s);
    return out;
  }
  LayerSource before, after;
  before.name = "before " + config.split_date;
  before.splits = {"train"};
  after.name = "from " + config.split_date;
  after.splits = {"test"};
  // log.date_captured is ISO (YYYY-MM-DD): text order is date order.
  for (nuscenes::Index s : scenes)
    (db.log[db.scene[s].log].date_captured < config.split_date ? before : after).scenes.push_back(s);
  out.push_back(std::move(before));
  out.push_back(std::move(after));
  return out;
}

const LayerSource& source_for(const std::vector<LayerSource>& sources, const std::string& split) {
  for (const LayerSource& s : sources)
    if (s.serves(split)) return s;
  throw InternalError("", split, "a layer source making tiles of the split");
}

void plan_time_split(const std::vector<LayerSource>& sources, const GenerateConfig& config, uint64_t seed,
                     std::vector<tiling::Region>& regions, std::vector<tiling::Crop>& crops, tiling::CropStats* stats) {
  const double res = config.resolution_m;
  for (const LayerSource& source : sources) {
    const std::string& split = source.splits.at(0);
    const tiling::CellWindow w = tiling::covered_window(source.layers.lidar);
    if (w.empty()) continue;  // no scene on this side of the date: an empty split (warned)
    const tiling::Region region{split + (split == "train" ? "-before" : "-after"),
                                split,
                                {static_cast<double>(w.col0) * res, static_cast<double>(w.row0) * res,
                                 static_cast<double>(w.col1) * res, static_cast<double>(w.row1) * res}};
    regions.push_back(region);
    tiling::CropStats side;
    for (const tiling::Crop& c : tiling::plan_crops(source.layers.lidar, {region}, config.crops, seed, &side))
      crops.push_back(c);
    if (stats) {
      const int i = tiling::split_index(split);
      stats->splits[static_cast<size_t>(i)] = side.splits[static_cast<size_t>(i)];
    }
  }
}

TimeSplitSides time_split_sides(const nuscenes::Database& db, const std::vector<LayerSource>& sources) {
  TimeSplitSides out;
  for (const LayerSource& source : sources) {
    (source.serves("train") ? out.before : out.after) += source.scenes.size();
    for (nuscenes::Index s : source.scenes) {
      const std::string& date = db.log[db.scene[s].log].date_captured;
      if (out.first_date.empty() || date < out.first_date) out.first_date = date;
      if (out.last_date.empty() || date > out.last_date) out.last_date = date;
    }
  }
  return out;
}

TimeSplitLeakage time_split_leakage(const std::vector<tiling::Crop>& crops, double resolution_m, int size_px) {
  std::vector<tiling::RectM> train;
  for (const tiling::Crop& c : crops)
    if (c.split == "train") train.push_back(c.bounds(resolution_m, size_px));
  TimeSplitLeakage out;
  std::vector<double> distances;
  const auto centre = [](const tiling::RectM& r) {
    return std::pair{(r.x_west_m + r.x_east_m) / 2.0, (r.y_south_m + r.y_north_m) / 2.0};
  };
  for (const tiling::Crop& c : crops) {
    if (c.split != "test") continue;
    ++out.test_tiles;
    const tiling::RectM t = c.bounds(resolution_m, size_px);
    double nearest = std::numeric_limits<double>::infinity();
    bool overlaps = false;
    for (const tiling::RectM& r : train) {
      const auto [tx, ty] = centre(t);
      const auto [rx, ry] = centre(r);
      nearest = std::min(nearest, std::hypot(tx - rx, ty - ry));
      overlaps = overlaps || (std::min(t.x_east_m, r.x_east_m) > std::max(t.x_west_m, r.x_west_m) &&
                              std::min(t.y_north_m, r.y_north_m) > std::max(t.y_south_m, r.y_south_m));
    }
    out.overlapping_train += overlaps;
    if (!train.empty()) distances.push_back(nearest);
  }
  if (!distances.empty()) {
    std::sort(distances.begin(), distances.end());
    const size_t n = distances.size();
    out.median_distance_m = n % 2 ? distances[n / 2] : (distances[n / 2 - 1] + distances[n / 2]) / 2.0;
  }
  return out;
}

nlohmann::ordered_json time_split_json(const GenerateConfig& config, const std::vector<LayerSource>& sources,
                                       const TimeSplitLeakage& leakage) {
  nlohmann::ordered_json scenes = nlohmann::ordered_json::object();
  for (const LayerSource& s : sources) scenes[s.splits.at(0)] = s.scenes.size();
  return {{"date", config.split_date},
          {"scenes", scenes},
          {"test_tiles", leakage.test_tiles},
          {"test_tiles_overlapping_train", leakage.overlapping_train},
          {"median_distance_to_train_m",
           leakage.median_distance_m ? nlohmann::ordered_json(std::round(*leakage.median_distance_m * 1000) / 1000)
                                     : nlohmann::ordered_json(nullptr)}};
}

}  // namespace nsg::pipeline
