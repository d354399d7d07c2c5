// `nsgraph segment`: class-id masks for the key-frame camera images from an ONNX
// segmentation model, in the layout `generate` reads (camera.semantic_root).
#include <optional>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/pipeline/segment.h"

namespace nsg::cli {
namespace {

struct SegmentCommandOptions {
  pipeline::SegmentOptions run;
  std::string dataroot, model, labels, out, schemas;
  std::optional<int> shard_index, num_shards;
};

int run_segment(SegmentCommandOptions& o, const Context& ctx) {
  o.run.dataroot = o.dataroot;
  o.run.model = o.model;
  o.run.labels = o.labels;
  o.run.out = o.out;
  o.run.schemas_dir = o.schemas;
  o.run.share = pipeline::resolve_share(o.shard_index, o.num_shards);
  o.run.progress = !ctx.quiet;
  const pipeline::SegmentSummary s = pipeline::segment_cameras(o.run);
  log::info(
      strprintf("segment: share %d of %d: %zu masks written, %zu already done (%zu images in all); %.1f s, "
                "%.2f images/s",
                o.run.share.index, o.run.share.count, s.written, s.skipped, s.images, s.seconds, s.images_per_s()));
  return kExitOk;
}

}  // namespace

void add_segment_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<SegmentCommandOptions>();
  CLI::App* cmd = root.add_subcommand(
      "segment", "Class-id masks of the key-frame camera images from an ONNX segmentation model (OpenCV dnn)");
  cmd->add_option("--dataroot", o->dataroot, "nuScenes dataroot")->required();
  cmd->add_option("--version", o->run.version, "Release version (v1.0-mini, v1.0-trainval, ...)")->required();
  cmd->add_option("--model", o->model, "ONNX model: input 1×3×H×W, output 1×C×h×w class scores")->required();
  cmd->add_option("--labels", o->labels,
                  "Labels file: input size and normalisation, output channel → our class "
                  "(samples/semantic-labels/*.json, schemas/v1/segment-labels.schema.json)")
      ->required();
  cmd->add_option("--out", o->out,
                  "Mask root: writes <out>/<CHANNEL>/<jpeg basename>.png (generate's "
                  "camera.semantic_root)")
      ->required();
  cmd->add_option("--channels", o->run.channels, "Camera channels (default: every camera)")->delimiter(',');
  add_threads_option(cmd, o->run.threads, "Images in parallel, one model each");
  cmd->add_option("--mask-scale", o->run.mask_scale_denom,
                  "Write masks at 1/N of the image's size (default 2: the scale generate samples at, "
                  "camera.jpeg_scale_denom; 1 = full size)")
      ->check(CLI::Range(1, 8));
  cmd->add_option("--shard-index", o->shard_index, "This process's share of the images (with --num-shards)");
  cmd->add_option("--num-shards", o->num_shards, "Number of processes sharing the images");
  cmd->add_option("--schemas", o->schemas, "Folder of the published schemas (default: found next to the binary)");
  cmd->callback([o, &ctx] { ctx.run = [o, &ctx] { return run_segment(*o, ctx); }; });
}

}  // namespace nsg::cli
