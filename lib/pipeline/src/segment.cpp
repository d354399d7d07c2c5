#include "nsg/pipeline/segment.h"

#include <algorithm>
#include <chrono>
#include <optional>

#include "nsg/core/atomic_file.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/output_folder.h"
#include "nsg/core/parallel.h"
#include "nsg/core/progress.h"
#include "nsg/core/strings.h"
#include "nsg/nuscenes/camera.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/semantic_mask.h"
#include "nsg/segment/labels.h"
#include "nsg/segment/model.h"

namespace nsg::pipeline {

namespace fs = std::filesystem;
using nuscenes::Database;
using nuscenes::Index;

void SegmentOptions::validate() const {
  if (dataroot.empty()) throw ConfigError("", "--dataroot", "a nuScenes dataroot");
  if (version.empty()) throw ConfigError("", "--version", "a release version (v1.0-mini, v1.0-trainval, …)");
  if (model.empty()) throw ConfigError("", "--model", "an ONNX segmentation model");
  if (labels.empty()) throw ConfigError("", "--labels", "a labels file (samples/semantic-labels/*.json)");
  if (out.empty()) throw ConfigError("", "--out", "the mask folder to write");
  if (threads < 0) throw ConfigError("", "--threads", "0 (all cores) or more");
  if (mask_scale_denom < 1 || mask_scale_denom > 8) throw ConfigError("", "--mask-scale", "an integer in 1..8");
  share.validate();
}

namespace {

struct ImageItem {
  Index sample_data;
  fs::path jpeg;
  std::string mask_relative;  // <channel>/<image stem>.png inside --out
  fs::path mask;              // the same, checked by OutputFolder (no link on the way)
};

// Every key-frame camera image of the chosen channels, in sample_data order.
std::vector<ImageItem> plan_items(const Database& db, const SegmentOptions& o, const OutputFolder& out) {
  for (const std::string& ch : o.channels) {
    const Index s = db.sensor_by_channel(ch);
    if (s == nuscenes::kNoIndex || db.sensor[s].modality != nuscenes::Modality::kCamera)
      throw ConfigError("", "--channels " + ch, "a camera channel of the release (CAM_FRONT, CAM_BACK, …)");
  }
  std::vector<ImageItem> items;
  for (Index i = 0; i < static_cast<Index>(db.sample_data.size()); ++i) {
    const nuscenes::SampleData& sd = db.sample_data[i];
    if (sd.modality != nuscenes::Modality::kCamera || !sd.is_key_frame) continue;
    const std::string& channel = db.channel(sd);
    if (!o.channels.empty() && std::find(o.channels.begin(), o.channels.end(), channel) == o.channels.end()) continue;
    // The channel from the release becomes a folder: checked as one plain name first.
    safe_name(channel, (o.dataroot / o.version / "sensor.json").string(), "channel of sample_data " + sd.token.str());
    // The path generate's plan_images reads (raster/color_layer.cpp).
    const std::string relative = channel + "/" + fs::path(sd.filename).stem().string() + ".png";
    items.push_back({i, db.file_path(sd), relative, out.path(relative)});
  }
  return items;
}

// A mask a previous run finished: readable, the image's size at `denom`, only our class ids or void.
bool valid_mask(const fs::path& file, int width, int height, int denom) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return false;
  try {
    const nuscenes::GrayImage m = nuscenes::read_semantic_mask(file);
    if (m.width != (width + denom - 1) / denom || m.height != (height + denom - 1) / denom) return false;
    const auto classes = static_cast<uint8_t>(segment::class_names().size());
    return std::all_of(m.pixels.begin(), m.pixels.end(), [&](uint8_t v) { return v < classes || v == segment::kVoid; });
  } catch (const Error&) {
    return false;
  }
}

void segment_image(const Database& db, const ImageItem& item, const OutputFolder& out,
                   segment::SegmentationModel& model, nuscenes::JpegDecoder& decoder, int mask_scale_denom) {
  const nuscenes::SampleData& sd = db.sample_data[item.sample_data];
  nuscenes::RgbImage image;
  decoder.decode_file(item.jpeg, nuscenes::JpegScale::kFull, image);
  if (image.width != sd.width || image.height != sd.height)
    throw DataError(item.jpeg.string(), "sample_data " + sd.token.str(),
                    strprintf("an image of the sample_data's size %d×%d (got %d×%d)", sd.width, sd.height, image.width,
                              image.height));
  nuscenes::GrayImage mask;
  model.segment(image, mask, mask_scale_denom);
  const std::vector<uint8_t> png = segment::encode_mask_png(mask);
  out.write(item.mask_relative, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace

SegmentSummary segment_cameras(const SegmentOptions& o) {
  o.validate();
  // Labels and model first: a bad file fails before the release is read.
  const segment::SegmentLabels labels = segment::load_labels(o.labels, o.schemas_dir);
  std::optional<segment::SegmentationModel> probe(std::in_place, o.model, labels);
  const Database db = Database::load(o.dataroot, o.version);
  refuse_out_over_input(o.out, o.dataroot, "--dataroot");
  const OutputFolder out(o.out);
  const std::vector<ImageItem> items = plan_items(db, o, out);
  SegmentSummary summary;
  summary.images = items.size();
  std::vector<const ImageItem*> todo;
  for (size_t j = 0; j < items.size(); ++j) {
    if (j % static_cast<size_t>(o.share.count) != static_cast<size_t>(o.share.index)) continue;
    ++summary.mine;
    const nuscenes::SampleData& sd = db.sample_data[items[j].sample_data];
    if (valid_mask(items[j].mask, sd.width, sd.height, o.mask_scale_denom)) {
      ++summary.skipped;
      continue;
    }
    todo.push_back(&items[j]);
  }
  log::info(strprintf("segment: share %d of %d: %zu of %zu key-frame images, %zu already done; model %s (%d channels)",
                      o.share.index, o.share.count, summary.mine, summary.images, summary.skipped,
                      o.model.filename().string().c_str(), probe->channels()));
  if (todo.empty()) return summary;

  // One model per lane (lanes run one image at a time); the probe serves as the first.
  const size_t lanes = lane_count(todo.size(), o.threads);
  std::vector<segment::SegmentationModel> models;
  models.push_back(std::move(*probe));
  probe.reset();
  while (models.size() < lanes) models.emplace_back(o.model, labels);
  std::vector<nuscenes::JpegDecoder> decoders(lanes);
  const int previous_cv_threads = segment::set_opencv_threads(1);
  Progress progress("segment images", todo.size(), o.progress);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    parallel_for_lanes(todo.size(), o.threads, [&](size_t lane, size_t i) {
      segment_image(db, *todo[i], out, models[lane], decoders[lane], o.mask_scale_denom);
      progress.advance();
    });
  } catch (...) {
    segment::set_opencv_threads(previous_cv_threads);
    throw;
  }
  segment::set_opencv_threads(previous_cv_threads);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary.written = todo.size();
  progress.set_detail(strprintf("%.2f images/s", summary.images_per_s()));
  progress.finish();
  return summary;
}

}  // namespace nsg::pipeline
