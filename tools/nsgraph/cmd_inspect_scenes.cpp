// `nsgraph inspect scenes` and `inspect samples --scene S`: what a release holds, as the
// devkit's list_scenes / list_samples show it, as JSON on stdout — the scene names
// export-cloud takes and the sample_data tokens inspect sweep takes.
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/nuscenes/database.h"
#include "nsg/pipeline/export_cloud.h"

namespace nsg::cli {
namespace {

struct InspectReleaseOptions {
  std::string dataroot;
  std::string version = "v1.0-mini";
  std::string scene;  // samples only
};

using nlohmann::ordered_json;

// fn(sample index) along the scene's first_sample → next chain, in time order; bounded by
// the table's size, so a cycle in a hostile table's next links ends.
template <typename Fn>
void for_each_sample(const nuscenes::Database& db, nuscenes::Index scene, Fn fn) {
  size_t steps = 0;
  for (nuscenes::Index k = db.scene[scene].first_sample; k != nuscenes::kNoIndex && steps < db.sample.size();
       k = db.sample[k].next, ++steps)
    fn(k);
}

ordered_json scene_json(const nuscenes::Database& db, nuscenes::Index s) {
  const nuscenes::Scene& scene = db.scene[s];
  const int64_t first = scene.first_sample != nuscenes::kNoIndex ? db.sample[scene.first_sample].timestamp_us : 0;
  const int64_t last = scene.last_sample != nuscenes::kNoIndex ? db.sample[scene.last_sample].timestamp_us : 0;
  size_t annotations = 0;
  for_each_sample(db, s, [&](nuscenes::Index k) { annotations += db.sample[k].anns.size(); });
  return {{"name", scene.name},
          {"token", scene.token.str()},
          {"location", scene.log != nuscenes::kNoIndex ? db.log[scene.log].location : ""},
          {"description", scene.description},
          {"samples", scene.nbr_samples},
          {"annotations", annotations},
          {"first_timestamp_us", first},
          {"duration_s", static_cast<double>(last - first) / 1e6}};
}

int run_scenes(const InspectReleaseOptions& o) {
  const nuscenes::Database db = nuscenes::Database::load(o.dataroot, o.version);
  ordered_json scenes = ordered_json::array();
  for (nuscenes::Index s = 0; s < static_cast<nuscenes::Index>(db.scene.size()); ++s)
    scenes.push_back(scene_json(db, s));
  std::cout << ordered_json{{"version", o.version}, {"scenes", scenes}}.dump(2) << "\n";
  return kExitOk;
}

// A scene's samples in time order (the first_sample → next chain), each with its
// key-frame sample_data token per channel.
int run_samples(const InspectReleaseOptions& o) {
  const nuscenes::Database db = nuscenes::Database::load(o.dataroot, o.version);
  const nuscenes::Index s = pipeline::find_scene(db, o.scene);
  ordered_json samples = ordered_json::array();
  for_each_sample(db, s, [&](nuscenes::Index k) {
    const nuscenes::Sample& sample = db.sample[k];
    ordered_json data = ordered_json::object();
    for (const nuscenes::SampleDataRef& ref : sample.data)
      data[db.sensor[ref.sensor].channel] = db.sample_data[ref.sample_data].token.str();
    samples.push_back({{"token", sample.token.str()},
                       {"timestamp_us", sample.timestamp_us},
                       {"annotations", sample.anns.size()},
                       {"sample_data", data}});
  });
  std::cout << ordered_json{{"scene", scene_json(db, s)}, {"samples", samples}}.dump(2) << "\n";
  return kExitOk;
}

void add_release_options(CLI::App* cmd, InspectReleaseOptions& o) {
  cmd->add_option("--dataroot", o.dataroot, "nuScenes dataroot folder")->required();
  cmd->add_option("--version", o.version, "Release version folder (v1.0-mini, v1.0-trainval, ...)")
      ->capture_default_str();
}

}  // namespace

void add_inspect_scenes(CLI::App& inspect, Context& ctx) {
  auto scenes = std::make_shared<InspectReleaseOptions>();
  CLI::App* cmd = inspect.add_subcommand(
      "scenes", "List the release's scenes: name, token, location, description, samples, duration (JSON)");
  add_release_options(cmd, *scenes);
  cmd->callback([scenes, &ctx] { ctx.run = [scenes] { return run_scenes(*scenes); }; });

  auto samples = std::make_shared<InspectReleaseOptions>();
  CLI::App* s = inspect.add_subcommand(
      "samples", "List one scene's samples in time order with their key-frame sample_data tokens per channel (JSON)");
  add_release_options(s, *samples);
  s->add_option("--scene", samples->scene, "Scene name (`nsgraph inspect scenes` lists them)")->required();
  s->callback([samples, &ctx] { ctx.run = [samples] { return run_samples(*samples); }; });
}

}  // namespace nsg::cli
