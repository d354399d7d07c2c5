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
  for (const ShardEntry& s : manifest_.shards) names.insert(s.split);
  return {names.begin(), names.end()};
}

std::optional<std::string> Dataset::split_of_keys(const std::vector<std::string>& keys, std::string& why) const {
  struct Range {
    std::string split, first, last;
  };
  std::vector<Range> ranges;
  for (const ShardEntry& s : manifest_.shards) ranges.push_back({s.split, s.first_key, s.last_key});
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
  NSG_CHECK(std::find(known.begin(), known.end(), split) != known.end(), DataError, manifest_file(),
            "split '" + split + "'",
            "a split the manifest lists (" + (known.empty() ? std::string("none") : join(known, ", ")) + ")");
}

SplitVerification Dataset::verify_split(const std::string& split, bool hash) const {
  const std::string manifest = manifest_file();
  NSG_CHECK(!split.empty(), DataError, manifest, "split", "a split name");
  require_split(split);
  SplitVerification out;
  out.hashed = hash;
  std::set<fs::path> listed;      // shard files (tar) or tile folders (folder layout)
  std::set<fs::path> shard_dirs;  // where the split's shards live
  const bool tar = tar_layout();
  for (const ShardEntry& shard : shards(split)) {
    const std::string& name = shard.name;
    const std::string record = "shard '" + name + "'";
    const int64_t want_bytes = shard.bytes;
    const std::string& want_sha = shard.sha256;
    out.tiles += shard.tiles;
    ++out.shards;
    if (tar) {
      const fs::path file = path_in_dataset(root_, shard.file, record + " file");
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
    const std::string& folder_rel = shard.folder;
    const fs::path folder = path_in_dataset(root_, folder_rel, record + " folder");
    NSG_CHECK(fs::is_directory(folder), IoError, folder.string(), name, "the shard's tile folder (missing)");
    const std::vector<fs::path> dirs = tile_folders(folder, shard.first_key, shard.last_key);
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
  if (tar && !rung_split(split))
    for (const ShardEntry& shard : rung_shards(split)) listed.insert((root_ / shard.file).lexically_normal());
  // Leftovers: a shard of this split (tar) or a tile folder (folder layout) in the same
  // place that the manifest does not list, e.g. from an earlier run with more tiles.
  for (const fs::path& dir : shard_dirs) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string base = e.path().filename().string();
      const bool candidate =
          tar ? (e.is_regular_file() && starts_with(base, split + "-") && ends_with(base, ".tar")) : e.is_directory();
      NSG_CHECK(!candidate || listed.count(e.path().lexically_normal()), DataError, e.path().string(), split,
                std::string(tar ? "only shards" : "only tile folders") + " the manifest lists for split '" + split +
                    "' (left from an earlier run? remove it or regenerate with --overwrite)");
    }
  }
  return out;
}

}  // namespace nsg::io
