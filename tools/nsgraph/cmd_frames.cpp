// `nsgraph frames`: the key frames of a release on a dataset's leak-free regions, in
// OpenLane-V2's per-frame layout (lib/frames, docs/frames.md).
#include <array>
#include <iostream>
#include <optional>

#include "commands.h"
#include "config_flags.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/frames/config.h"
#include "nsg/frames/export.h"
#include "nsg/frames/render.h"
#include "nsg/tiling/regions.h"

namespace nsg::cli {
namespace {

struct FramesCliOptions {
  std::string dataset;
  std::string out;
  std::shared_ptr<ConfigArgs> config = std::make_shared<ConfigArgs>();
  bool stats = false;
  bool overwrite = false;
};

std::string share_text(const frames::Leakage& l) {
  if (!l.share_within) return "no test frames";
  std::string text =
      strprintf("%.1f %% of %lld test frames", 100.0 * *l.share_within, static_cast<long long>(l.test_frames));
  if (l.median_distance_m) text += strprintf(", median %.1f m", *l.median_distance_m);
  return text;
}

// Why the train or test split got no frame, by the counts of the frames dropped, and the option that keeps
// them. A split without frames is a warning; an export without any is a failed run (exit 1,
// like generate's empty run): false then.
bool explain_empty_splits(const frames::FramesSummary& s) {
  std::array<int64_t, 3> per_split{};
  for (const auto& [location, counts] : s.frames)
    for (size_t k = 0; k < counts.size(); ++k) per_split[k] += counts[k];
  std::vector<std::string> empty;
  for (size_t k = 0; k < per_split.size(); ++k)  // val is optional: a dataset may have none
    if (per_split[k] == 0 && tiling::kSplitNames[k] != "val") empty.emplace_back(tiling::kSplitNames[k]);
  if (empty.empty()) return true;
  const frames::DropCounts& d = s.dropped;
  const std::string why = strprintf(
      "of the release's %lld key frames, %lld lie outside every region of the dataset (its splits.regions), %lld "
      "come nearer than the split buffer to another split's region (dropped by --overlap drop; --overlap keep or "
      "flag keeps them), %lld are of another location, %lld of an excluded scene and %lld have no ego pose",
      static_cast<long long>(s.key_frames), static_cast<long long>(d.outside_regions),
      static_cast<long long>(d.overlap), static_cast<long long>(d.other_location),
      static_cast<long long>(d.excluded_scene), static_cast<long long>(d.no_ego_pose));
  if (s.total_frames() == 0) {
    log::error("frames: no frame kept in any split: " + why + "; the manifest records the counts");
    return false;
  }
  log::warn("frames: no frame in split(s) " + join(empty, ", ") + ": " + why);
  return true;
}

int run_frames(const FramesCliOptions& o, const Context& ctx) {
  if (list_options_if_asked(*o.config, "frames",
                            "Every option of the per-key-frame export (OpenLane-V2's layout on the dataset's "
                            "regions), as declared; a file may give any subset.",
                            frames::frames_option_table(), frames::frames_config_schema()))
    return kExitOk;
  const frames::FramesConfig config =
      frames::resolve_frames_config(o.config->config_path, o.config->settings, o.config->flags);
  if (print_config_if_asked(*o.config, frames::frames_option_table(), config)) return kExitOk;
  NSG_CHECK(!o.dataset.empty(), ConfigError, "", "--dataset", "a generated dataset folder (manifest.json)");
  NSG_CHECK(o.stats || !o.out.empty(), ConfigError, "", "--out", "an output folder (or --stats to only count)");
  frames::FramesRun run;
  run.dataset = o.dataset;
  run.out = o.out;
  run.overwrite = o.overwrite;
  run.stats_only = o.stats;
  run.progress = !ctx.quiet;
  const frames::FramesSummary s = frames::export_frames(config, run);
  if (o.stats) {
    std::cout << frames::summary_json(s, config).dump(2) << "\n";
    return kExitOk;
  }
  if (!explain_empty_splits(s)) return kExitProblems;
  log::info(strprintf("frames: within %.1f m of a train frame: %s (regions); %s (scenes-random, seed %llu)",
                      config.leak_radius_m, share_text(s.regions).c_str(), share_text(s.scenes_random).c_str(),
                      static_cast<unsigned long long>(config.seed)));
  log::info("frames: " + std::to_string(s.files) + " files written to " + o.out);
  return kExitOk;
}

int run_render(const frames::RenderRequest& r) {
  NSG_CHECK(!r.export_dir.empty(), ConfigError, "", "--export", "a frames export folder (manifest.json)");
  NSG_CHECK(!r.frame.empty(), ConfigError, "", "--frame", "a sample token or split/segment_id/timestamp");
  const frames::RenderedFrame done = frames::render_frame(r);
  std::string drawn;
  for (const auto& [channel, n] : done.truth_pieces_per_camera) drawn += " " + channel + ":" + std::to_string(n);
  log::info("frames render: " + done.sample_token + ", ground-truth pieces in view per camera:" + drawn + "; " +
            std::to_string(done.files.size()) + " files written to " + r.out.string());
  return kExitOk;
}

// `nsgraph frames render`: one frame drawn into its cameras and from above.
CLI::App* add_render_command(CLI::App& frames_cmd, Context& ctx) {
  auto r = std::make_shared<frames::RenderRequest>();
  CLI::App* cmd = frames_cmd.add_subcommand(
      "render", "Draw one frame's centerlines (and a submission's) into its camera images and a BEV panel");
  cmd->add_option("--export", r->export_dir, "A frames export (nsgraph frames --out)");
  cmd->add_option("--frame", r->frame, "The frame: its sample token or split/segment_id/timestamp");
  cmd->add_option("--split", r->split, "The split the frame is in (default test)")->capture_default_str();
  cmd->add_option("--submission", r->submission, "A results file to draw beside the ground truth (magenta)");
  cmd->add_option("--out", r->out, "Output folder: <CHANNEL>.jpg per camera, bev.png, render.json");
  cmd->add_option("--bev-px-per-m", r->bev_px_per_m, "Scale of the BEV panel (default 10 px per metre)")
      ->capture_default_str();
  cmd->add_flag("--overwrite", r->overwrite, "Replace an earlier render in --out (only the files it listed)");
  cmd->add_flag(
      "--no-verify", [r](int64_t) { r->verify = false; }, "Skip the record's sha256 check");
  cmd->callback([r, &ctx] { ctx.run = [r] { return run_render(*r); }; });
  return cmd;
}

}  // namespace

void add_frames_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<FramesCliOptions>();
  CLI::App* cmd = root.add_subcommand(
      "frames", "Export every key frame in a dataset's regions as OpenLane-V2 frame records (cameras, pose, lanes)");
  cmd->add_option("--dataset", o->dataset, "A generated dataset (its manifest gives the release, regions and map)");
  cmd->add_option("--out", o->out, "Output folder");
  add_config_options(cmd, o->config, "Frames config JSON (any subset of the keys; --list-options)");
  const auto& table = frames::frames_option_table();
  add_key_flag(cmd, o->config, table, "--dataroot", "dataroot", nullptr,
               "The release, when it moved since generate (config key dataroot)");
  add_key_flag(cmd, o->config, table, "--overlap", "overlap", nullptr,
               "A frame whose window comes near another split's region: drop (default), keep or flag (config key "
               "overlap)");
  add_key_flag(cmd, o->config, table, "--split-preset", "split_preset", nullptr,
               "regions (default: the dataset's leak-free regions) or scenes-random (a seeded draw per scene, as "
               "nuScenes' own split; it leaks) (config key split_preset)");
  add_key_flag(cmd, o->config, table, "--copy-images", "copy_images", "true",
               "Copy the camera images next to the records (hard links where possible; config key copy_images)");
  cmd->add_flag("--stats", o->stats,
                "Count the frames and print the leakage figures of both split presets as JSON; write nothing");
  cmd->add_flag("--overwrite", o->overwrite, "Replace a frames export already in --out");
  CLI::App* render = add_render_command(*cmd, ctx);
  cmd->callback([o, render, &ctx] {
    if (render->parsed()) return;  // `frames render` set its own run
    ctx.run = [o, &ctx] { return run_frames(*o, ctx); };
  });
}

}  // namespace nsg::cli
