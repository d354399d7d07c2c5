// Dataset::verify_split: the manifest is the one list of a split's shards and their bytes,
// so what is scored is what was generated — not whatever matches a file name pattern.
#include <algorithm>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/io/dataset.h"
#include "nsg/io/tile_members.h"

namespace nsg::io {

namespace fs = std::filesystem;

namespace {

std::string text_field(const nlohmann::json& entry, const char* name, const std::string& manifest,
                       const std::string& record) {
  NSG_CHECK(entry.is_object() && entry.contains(name) && entry[name].is_string(), ParseError, manifest,
            record + "/" + name, "a string");
  return entry[name].get<std::string>();
}

int64_t count_field(const nlohmann::json& entry, const char* name, const std::string& manifest,
                    const std::string& record) {
  NSG_CHECK(entry.contains(name) && entry[name].is_number_integer() && entry[name].get<int64_t>() >= 0, ParseError,
            manifest, record + "/" + name, "a non-negative integer");
  return entry[name].get<int64_t>();
}

// The tile folders of a folder-layout shard: tiles/<split>/<key> for keys in [first, last].
std::vector<fs::path> tile_folders(const fs::path& folder, const std::string& first, const std::string& last) {
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string key = e.path().filename().string();
    if (e.is_directory() && key >= first && key <= last) dirs.push_back(e.path());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

// The generator's digest of a folder shard (pipeline item_digest): sha256 over the lines
// "<file relative to the dataset>\0<sha256>\n" of its tiles in key order, each tile's
// members in tile_members() order.
std::string folder_digest(const fs::path& root, const std::string& folder_rel, const std::vector<fs::path>& dirs,
                          int64_t* bytes) {
  std::string lines;
  *bytes = 0;
  for (const fs::path& dir : dirs) {
    const std::string key = dir.filename().string();
    for (const TileMember& m : tile_members()) {
      const std::string rel = folder_rel + "/" + key + "/" + key + "." + m.file;
      const fs::path file = root / rel;
      NSG_CHECK(fs::is_regular_file(file), IoError, file.string(), key, "the tile's " + m.file + " (missing)");
      *bytes += static_cast<int64_t>(fs::file_size(file));
      lines += rel + '\0' + sha256_file(file) + "\n";
    }
  }
  return sha256_hex(lines);
}

}  // namespace

std::vector<std::string> Dataset::splits() const {
  std::set<std::string> names;
  for (const nlohmann::json& s : manifest_["shards"])
    if (s.is_object() && s.contains("split") && s["split"].is_string()) names.insert(s["split"].get<std::string>());
  return {names.begin(), names.end()};
}

std::optional<std::string> Dataset::split_of_keys(const std::vector<std::string>& keys, std::string& why) const {
  struct Range {
    std::string split, first, last;
  };
  std::vector<Range> ranges;
  for (const nlohmann::json& s : manifest_["shards"]) {
    if (!s.is_object()) continue;
    const auto text = [&](const char* name) {
      const auto it = s.find(name);
      return it != s.end() && it->is_string() ? it->get<std::string>() : std::string();
    };
    if (!text("split").empty()) ranges.push_back({text("split"), text("first_key"), text("last_key")});
  }
  std::map<std::string, int64_t> counts;
  for (const std::string& key : keys) {
    std::set<std::string> in;  // a key in the ranges of two splits counts for both
    for (const Range& r : ranges)
      if (key >= r.first && key <= r.last) in.insert(r.split);
    for (const std::string& split : in) ++counts[split];
  }
  if (counts.size() == 1) return counts.begin()->first;
  if (counts.empty()) {
    why =
        strprintf("none of its %zu keys is a tile of any of this dataset's splits (e.g. '%s'; splits: %s)", keys.size(),
                  keys.empty() ? "" : printable_text(keys.front()).c_str(), join(splits(), ", ").c_str());
  } else {
    std::string found;
    for (const auto& [split, n] : counts)
      found += strprintf("%s%s: %lld", found.empty() ? "" : ", ", split.c_str(), static_cast<long long>(n));
    why = "they fall in several (" + found + "); give --split";
  }
  return std::nullopt;
}

void Dataset::require_split(const std::string& split) const {
  if (split.empty()) return;
  const std::vector<std::string> known = split_names();
  NSG_CHECK(std::find(known.begin(), known.end(), split) != known.end(), DataError, (root_ / "manifest.json").string(),
            "split '" + split + "'",
            "a split the manifest lists (" + (known.empty() ? std::string("none") : join(known, ", ")) + ")");
}

SplitVerification Dataset::verify_split(const std::string& split, bool hash) const {
  const std::string manifest = (root_ / "manifest.json").string();
  NSG_CHECK(!split.empty(), DataError, manifest, "split", "a split name");
  require_split(split);
  SplitVerification out;
  out.hashed = hash;
  std::set<fs::path> listed;      // shard files (tar) or tile folders (folder layout)
  std::set<fs::path> shard_dirs;  // where the split's shards live
  for (const nlohmann::json& shard : shards(split)) {
    const std::string name = text_field(shard, "name", manifest, "shards");
    const std::string record = "shard '" + name + "'";
    const int64_t want_bytes = count_field(shard, "bytes", manifest, record);
    const std::string want_sha = text_field(shard, "sha256", manifest, record);
    out.tiles += count_field(shard, "tiles", manifest, record);
    ++out.shards;
    if (tar_) {
      const fs::path file = path_in_dataset(root_, text_field(shard, "file", manifest, record), record + " file");
      NSG_CHECK(fs::is_regular_file(file), IoError, file.string(), name,
                "the shard the manifest lists for split '" + split + "' (missing)");
      const auto bytes = static_cast<int64_t>(fs::file_size(file));
      NSG_CHECK(bytes == want_bytes, DataError, file.string(), name,
                strprintf("%lld bytes as the manifest records, found %lld (changed after generation?)",
                          static_cast<long long>(want_bytes), static_cast<long long>(bytes)));
      if (hash) {
        const std::string got = sha256_file(file);
        NSG_CHECK(got == want_sha, DataError, file.string(), name,
                  "sha256 " + want_sha + " as the manifest records, found " + got + " (changed after generation?)");
      }
      listed.insert(file.lexically_normal());
      shard_dirs.insert(file.parent_path().lexically_normal());
      continue;
    }
    const std::string folder_rel = text_field(shard, "folder", manifest, record);
    const fs::path folder = path_in_dataset(root_, folder_rel, record + " folder");
    NSG_CHECK(fs::is_directory(folder), IoError, folder.string(), name, "the shard's tile folder (missing)");
    const std::vector<fs::path> dirs = tile_folders(folder, text_field(shard, "first_key", manifest, record),
                                                    text_field(shard, "last_key", manifest, record));
    for (const fs::path& d : dirs) listed.insert(d.lexically_normal());
    shard_dirs.insert(folder.lexically_normal());
    if (hash) {
      int64_t bytes = 0;
      const std::string got = folder_digest(root_, folder_rel, dirs, &bytes);
      NSG_CHECK(
          got == want_sha && bytes == want_bytes, DataError, folder.string(), name,
          strprintf("the digest %s over %lld bytes the manifest records, found %s over %lld bytes "
                    "(a tile changed, added or removed after generation?)",
                    want_sha.c_str(), static_cast<long long>(want_bytes), got.c_str(), static_cast<long long>(bytes)));
    }
  }
  // The ladder's shards of the split (generate --ladder) share the shards/ folder.
  if (tar_ && !rung_split(split))
    for (const nlohmann::json& shard : rung_shards(split))
      if (shard.contains("file") && shard["file"].is_string())
        listed.insert((root_ / shard["file"].get<std::string>()).lexically_normal());
  // Leftovers: a shard of this split (tar) or a tile folder (folder layout) in the same
  // place that the manifest does not list, e.g. from an earlier run with more tiles.
  for (const fs::path& dir : shard_dirs) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string base = e.path().filename().string();
      const bool candidate =
          tar_ ? (e.is_regular_file() && starts_with(base, split + "-") && ends_with(base, ".tar")) : e.is_directory();
      NSG_CHECK(!candidate || listed.count(e.path().lexically_normal()), DataError, e.path().string(), split,
                std::string(tar_ ? "only shards" : "only tile folders") + " the manifest lists for split '" + split +
                    "' (left from an earlier run? remove it or regenerate with --overwrite)");
    }
  }
  return out;
}

}  // namespace nsg::io
