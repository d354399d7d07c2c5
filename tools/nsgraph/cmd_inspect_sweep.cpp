// `nsgraph inspect sweep`: one LiDAR sweep in the global frame (sensor → ego → global with
// the sweep's own ego pose, docs/nuscenes-input.md), as JSON on stdout.
#include <charconv>
#include <cstdio>
#include <optional>
#include <string>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/nuscenes/database.h"
#include "nsg/nuscenes/lidar.h"

namespace nsg::cli {

namespace {

struct InspectSweepOptions {
  std::string dataroot;
  std::string version = "v1.0-mini";
  std::string token;
  std::optional<long long> head;  // print only the first N points

  void validate() const {
    if (dataroot.empty()) throw ConfigError("", "--dataroot", "a dataroot folder");
    if (version.empty()) throw ConfigError("", "--version", "a release version such as v1.0-mini");
    if (!nuscenes::Token::parse(token) || token.empty()) {
      throw ConfigError("", "--token " + token, "a sample_data token of 32 lowercase hex chars");
    }
    if (head && *head < 0) throw ConfigError("", "--head", "a non-negative number of points");
  }
};

// Shortest text that reads back as the same float32.
void append_float(std::string& out, float value) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}

std::string sweep_json(const std::string& token, const std::vector<nuscenes::LidarPoint>& points, size_t count) {
  std::string out;
  out.reserve(64 + count * 48);
  out += "{\"token\": \"" + token + "\", \"count\": " + std::to_string(count) +
         ", \"total\": " + std::to_string(points.size()) + ", \"points\": [";
  for (size_t i = 0; i < count; ++i) {
    const nuscenes::LidarPoint& p = points[i];
    out += i == 0 ? "[" : ", [";
    append_float(out, p.x);
    out += ", ";
    append_float(out, p.y);
    out += ", ";
    append_float(out, p.z);
    out += ", ";
    append_float(out, p.intensity);
    out += "]";
  }
  out += "]}\n";
  return out;
}

int run_inspect_sweep(const InspectSweepOptions& options) {
  options.validate();
  const nuscenes::Database db = nuscenes::Database::load(options.dataroot, options.version);
  const nuscenes::Index sd = db.sample_data.find(nuscenes::Token::from_string(options.token));
  if (sd == nuscenes::kNoIndex) {
    throw DataError(db.sample_data.file(), "token " + options.token, "an existing sample_data token (not found)");
  }
  const std::vector<nuscenes::LidarPoint> points = nuscenes::load_sweep_global(db, sd);
  size_t count = points.size();
  if (options.head && static_cast<unsigned long long>(*options.head) < count)
    count = static_cast<size_t>(*options.head);
  const std::string json = sweep_json(options.token, points, count);
  std::fwrite(json.data(), 1, json.size(), stdout);
  return std::fflush(stdout) == 0 ? kExitOk : kExitInternal;
}

}  // namespace

void add_inspect_sweep(CLI::App& parent, Context& ctx) {
  auto options = std::make_shared<InspectSweepOptions>();
  CLI::App* cmd = parent.add_subcommand("sweep", "Print one LiDAR sweep in the global frame (JSON)");
  cmd->add_option("--dataroot", options->dataroot, "nuScenes dataroot folder")->required();
  cmd->add_option("--version", options->version, "Release version folder")->capture_default_str();
  cmd->add_option("--token", options->token, "sample_data token of a LiDAR sweep")->required();
  cmd->add_option("--head", options->head, "Print only the first N points");
  cmd->callback([options, &ctx] { ctx.run = [options] { return run_inspect_sweep(*options); }; });
}

}  // namespace nsg::cli
