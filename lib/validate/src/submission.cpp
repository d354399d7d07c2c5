#include "nsg/validate/submission.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <set>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/core/json.h"
#include "nsg/core/strings.h"
#include "nsg/io/dataset.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/schema.h"

namespace nsg::validate {
namespace {

bool unread(const std::vector<bool>& flags, size_t k) { return k < flags.size() && flags[k]; }

// Sum of the lengths of the edges whose ends are read nodes within range (others are
// reported by the schema and index checks).
double edge_length_px(const TileValues& tile) {
  const auto n = static_cast<int64_t>(tile.nodes.size());
  const auto usable = [&](int64_t i) { return i >= 0 && i < n && !unread(tile.node_unread, static_cast<size_t>(i)); };
  double total = 0.0;
  for (size_t k = 0; k < tile.edges.size(); ++k) {
    const auto [i, j] = tile.edges[k];
    if (unread(tile.edge_unread, k) || !usable(i) || !usable(j)) continue;
    const auto& a = tile.nodes[static_cast<size_t>(i)];
    const auto& b = tile.nodes[static_cast<size_t>(j)];
    total += std::hypot(b[0] - a[0], b[1] - a[1]);
  }
  return total;
}

// A file's node as numbers: an array of two numbers, else unread (the schema reports it).
bool read_node(const nlohmann::json& n, std::array<double, 2>* out) {
  if (!n.is_array() || n.size() != 2 || !n[0].is_number() || !n[1].is_number()) return false;
  *out = {n[0].get<double>(), n[1].get<double>()};
  return true;
}

// A file's edge as indices: an array of two integers, else unread. An unsigned index above
// 2^63 − 1 cannot be held: it is reported here, as written, and the edge left unread.
bool read_edge(const nlohmann::json& e, size_t nodes, const std::string& at, Issues& issues,
               std::array<int64_t, 2>* out) {
  if (!e.is_array() || e.size() != 2 || !e[0].is_number_integer() || !e[1].is_number_integer()) return false;
  bool held = true;
  for (size_t s = 0; s < 2; ++s) {
    if (e[s].is_number_unsigned() && e[s].get<uint64_t>() > uint64_t{INT64_MAX}) {
      held = false;
      issues.error(
          "submission.indices", at + "/" + std::to_string(s),
          "node index " + std::to_string(e[s].get<uint64_t>()) + " out of range [0, " + std::to_string(nodes) + ")");
    } else {
      (*out)[s] = e[s].get<int64_t>();
    }
  }
  return held;
}

std::vector<double> read_scores(const nlohmann::json& tile, const char* name, bool* present) {
  std::vector<double> out;
  *present = tile.contains(name) && tile[name].is_array();
  if (!*present) return out;
  // A score that is no number is the schema's to report; 0 keeps the positions.
  for (const nlohmann::json& v : tile[name]) out.push_back(v.is_number() ? v.get<double>() : 0.0);
  return out;
}

// A file's tile as numbers, every element in its position.
TileValues tile_values(const nlohmann::json& tile, const std::string& base, Issues& issues) {
  TileValues out;
  if (const auto nodes = tile.find("nodes"); nodes != tile.end() && nodes->is_array()) {
    out.nodes.resize(nodes->size());
    out.node_unread.resize(nodes->size());
    for (size_t k = 0; k < nodes->size(); ++k) out.node_unread[k] = !read_node((*nodes)[k], &out.nodes[k]);
  }
  if (const auto edges = tile.find("edges"); edges != tile.end() && edges->is_array()) {
    out.edges.resize(edges->size());
    out.edge_unread.resize(edges->size());
    for (size_t k = 0; k < edges->size(); ++k)
      out.edge_unread[k] =
          !read_edge((*edges)[k], out.nodes.size(), base + "/edges/" + std::to_string(k), issues, &out.edges[k]);
  }
  out.node_scores = read_scores(tile, "node_scores", &out.has_node_scores);
  out.edge_scores = read_scores(tile, "edge_scores", &out.has_edge_scores);
  return out;
}

void check_coordinates(const TileValues& tile, const std::string& base, const SubmissionLimits& limits,
                       Issues& issues) {
  for (size_t k = 0; k < tile.nodes.size(); ++k) {
    if (unread(tile.node_unread, k)) continue;
    for (size_t s = 0; s < 2; ++s) {
      const double c = tile.nodes[k][s];
      if (!std::isfinite(c))
        issues.error("submission.finite", base + "/nodes/" + std::to_string(k) + "/" + std::to_string(s),
                     "a finite coordinate");
      else if (std::fabs(c) > limits.max_abs_coordinate_px)
        issues.error("submission.size", base + "/nodes/" + std::to_string(k) + "/" + std::to_string(s),
                     strprintf("a coordinate within ±%.0f px (the scoring limits: score --help), got %g",
                               limits.max_abs_coordinate_px, c));
    }
  }
}

void check_indices(const TileValues& tile, const std::string& base, Issues& issues) {
  const auto n = static_cast<int64_t>(tile.nodes.size());
  for (size_t k = 0; k < tile.edges.size(); ++k) {
    if (unread(tile.edge_unread, k)) continue;
    for (size_t s = 0; s < 2; ++s) {
      const int64_t idx = tile.edges[k][s];
      if (idx >= 0 && idx < n) continue;
      if (!issues.lists("submission.indices")) {  // counted only: no message to build
        issues.error("submission.indices", base, "");
        continue;
      }
      issues.error("submission.indices", base + "/edges/" + std::to_string(k) + "/" + std::to_string(s),
                   "node index " + std::to_string(idx) + " out of range [0, " + std::to_string(n) + ")");
    }
  }
}

void check_scores(const TileValues& tile, const std::string& base, Issues& issues) {
  const struct {
    const char* name;
    bool present;
    const std::vector<double>& scores;
    size_t want;
    const char* of;
  } lists[] = {{"node_scores", tile.has_node_scores, tile.node_scores, tile.nodes.size(), " nodes"},
               {"edge_scores", tile.has_edge_scores, tile.edge_scores, tile.edges.size(), " edges"}};
  for (const auto& l : lists) {
    if (!l.present) continue;
    if (l.scores.size() != l.want)
      issues.error("submission.scores", base + "/" + l.name,
                   std::to_string(l.scores.size()) + " scores for " + std::to_string(l.want) + l.of);
    for (size_t k = 0; k < l.scores.size(); ++k)
      if (!std::isfinite(l.scores[k]))
        issues.error("submission.finite", base + "/" + l.name + "/" + std::to_string(k), "a finite score");
  }
}

void check_tile(const std::string& key, const nlohmann::json& tile, const std::string& file,
                const SubmissionLimits& limits, Issues& issues) {
  if (!tile.is_object()) return;  // the schema reports it
  const std::string base = file + ":/tiles/" + json_pointer_token(key);
  check_tile_values(tile_values(tile, base, issues), base, limits, issues);
}

}  // namespace

Issues check_submission_structure(const nlohmann::json& doc, const std::string& file_label,
                                  const SubmissionLimits& limits) {
  Issues issues;
  issues.limit_per_check(kMaxListedIssues);
  if (!doc.is_object() || !doc.contains("tiles") || !doc["tiles"].is_object()) return issues;
  for (const auto& [key, tile] : doc["tiles"].items()) check_tile(key, tile, file_label, limits, issues);
  return issues;
}

void check_tile_values(const TileValues& tile, const std::string& base, const SubmissionLimits& limits,
                       Issues& issues) {
  const auto nodes = static_cast<int64_t>(tile.nodes.size()), edges = static_cast<int64_t>(tile.edges.size());
  std::vector<std::array<int64_t, 2>> pairs;  // the path work's edges: read ones, within range
  if (edges <= limits.max_edges_per_tile)
    for (size_t k = 0; k < tile.edges.size(); ++k)
      if (!unread(tile.edge_unread, k)) pairs.push_back(tile.edges[k]);
  check_tile_limits(nodes, edges, edge_length_px(tile), path_search_work(nodes, pairs), base, limits, issues);
  check_coordinates(tile, base, limits, issues);
  check_indices(tile, base, issues);
  check_scores(tile, base, issues);
}

int64_t path_search_work(int64_t nodes, const std::vector<std::array<int64_t, 2>>& edges) {
  std::vector<int64_t> parent(static_cast<size_t>(std::max<int64_t>(nodes, 0)));
  for (size_t k = 0; k < parent.size(); ++k) parent[k] = static_cast<int64_t>(k);
  const auto root = [&](int64_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& [i, j] : edges)
    if (i >= 0 && i < nodes && j >= 0 && j < nodes) parent[root(i)] = root(j);
  std::vector<int64_t> size(parent.size(), 0), arcs(parent.size(), 0);
  for (int64_t k = 0; k < nodes; ++k) ++size[root(k)];
  for (const auto& [i, j] : edges)
    if (i >= 0 && i < nodes && j >= 0 && j < nodes) arcs[root(i)] += 2;
  int64_t work = 0;
  for (size_t c = 0; c < size.size(); ++c) work += size[c] * (size[c] + arcs[c]);
  return work;
}

void check_tile_limits(int64_t nodes, int64_t edges, double edge_length_px, int64_t path_work,
                       const std::string& subject, const SubmissionLimits& limits, Issues& issues) {
  const std::string why = " (the scoring limits: score --help)";
  if (nodes > limits.max_nodes_per_tile)
    issues.error(
        "submission.size", subject + "/nodes",
        std::to_string(nodes) + " nodes; at most " + std::to_string(limits.max_nodes_per_tile) + " per tile" + why);
  if (edges > limits.max_edges_per_tile)
    issues.error(
        "submission.size", subject + "/edges",
        std::to_string(edges) + " edges; at most " + std::to_string(limits.max_edges_per_tile) + " per tile" + why);
  if (!(edge_length_px <= limits.max_edge_length_px_per_tile))  // NaN and inf included
    issues.error("submission.size", subject + "/edges",
                 strprintf("a total edge length of %.0f px; at most %.0f px per tile", edge_length_px,
                           limits.max_edge_length_px_per_tile) +
                     why);
  if (nodes <= limits.max_nodes_per_tile && edges <= limits.max_edges_per_tile &&
      path_work > limits.max_path_work_per_tile)
    issues.error(
        "submission.size", subject + "/edges",
        strprintf("a shortest-path work of %lld (per connected piece: nodes x (nodes + 2 x edges)); at most %lld "
                  "per tile, about %lld nodes in one connected piece",
                  static_cast<long long>(path_work), static_cast<long long>(limits.max_path_work_per_tile),
                  static_cast<long long>(std::sqrt(static_cast<double>(limits.max_path_work_per_tile) / 3.0))) +
            why);
}

std::string json_pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

}  // namespace nsg::validate

// ---------------------------------------------------------------------------------------
// Reading and validating a submission file.

namespace nsg::validate {

void SubmissionLimits::validate() const {
  NSG_CHECK(max_nodes_per_tile > 0 && max_edges_per_tile > 0 && max_edge_length_px_per_tile > 0 &&
                max_path_work_per_tile > 0 && max_search_work_per_tile > 0 && max_abs_coordinate_px > 0,
            ConfigError, "", "limits", "positive per-tile limits");
  NSG_CHECK(max_file_bytes > 0 && max_json_values > 0 && max_depth > 0, ConfigError, "", "limits",
            "positive file limits");
}

void SubmissionValidateOptions::validate() const {
  NSG_CHECK(!submission.empty(), ConfigError, "", "--submission", "a submission file");
  NSG_CHECK(!split.empty(), ConfigError, "", "--split", "a split name");
  limits.validate();
}

namespace {

// Counts values and depth without building anything; stops at the first limit.
class CountingSax : public nlohmann::json_sax<nlohmann::json> {
 public:
  explicit CountingSax(const SubmissionLimits& limits) : limits_(limits) {}
  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return open(); }
  bool key(string_t&) override { return true; }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& ex) override {
    problem_check = "submission.json";
    // The parser's own words without its exception id ("[json.exception.parse_error.101]").
    std::string reason = ex.what();
    if (const size_t cut = reason.find("] "); reason.rfind("[json.exception.", 0) == 0 && cut != std::string::npos)
      reason.erase(0, cut + 2);
    problem = "valid JSON (NaN and Infinity are not JSON; numbers must fit a double) at byte " +
              std::to_string(position) + ": " + printable_utf8(reason);
    return false;
  }

  std::string problem_check, problem;

 private:
  bool value() {
    if (++values_ <= limits_.max_json_values) return true;
    problem_check = "submission.size";
    problem = "at most " + std::to_string(limits_.max_json_values) + " JSON values in the file";
    return false;
  }
  bool open() {
    if (!value()) return false;
    if (++depth_ <= limits_.max_depth) return true;
    problem_check = "submission.size";
    problem = "nesting at most " + std::to_string(limits_.max_depth) + " deep";
    return false;
  }
  bool close() {
    --depth_;
    return true;
  }
  const SubmissionLimits& limits_;
  int64_t values_ = 0;
  int depth_ = 0;
};

}  // namespace

namespace {

std::string size_problem(int64_t limit_bytes, const std::string& got) {
  return strprintf("a file of at most %.0f MiB, got ", static_cast<double>(limit_bytes) / (1 << 20)) + got;
}

// The file's text, or nullopt with a submission.size issue beyond `limit_bytes`. A regular
// file is measured before it is read; a pipe (`<(…)`, /dev/stdin) has no size up front and
// is read up to one byte past the limit.
std::optional<std::string> read_bounded_text(const std::filesystem::path& file, int64_t limit_bytes, Issues& issues) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  // The problem first, then what the argument takes.
  if (ec || !std::filesystem::exists(status))
    throw IoError(file.string(), "", "cannot open: no such file (expected a submission JSON file)");
  if (std::filesystem::is_directory(status))
    throw IoError(file.string(), "",
                  "is a directory, not a submission: the JSON file `nsgraph predict` writes "
                  "(schemas/v1/submission.schema.json)");
  if (std::filesystem::is_regular_file(status)) {
    const auto bytes = std::filesystem::file_size(file, ec);
    if (ec) throw IoError(file.string(), "", "cannot read: " + ec.message() + " (expected a submission JSON file)");
    if (static_cast<int64_t>(bytes) > limit_bytes) {
      issues.error("submission.size", file.string(),
                   size_problem(limit_bytes, strprintf("%.1f MiB", static_cast<double>(bytes) / (1 << 20))));
      return std::nullopt;
    }
    return read_file(file);
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file.string(), "", "cannot open for reading (expected a submission file or stream)");
  std::string text;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (static_cast<int64_t>(text.size()) > limit_bytes) {
      issues.error("submission.size", file.string(), size_problem(limit_bytes, "a longer stream"));
      return std::nullopt;
    }
  }
  if (in.bad()) throw IoError(file.string(), "", "a readable submission stream");
  return text;
}

}  // namespace

std::optional<std::string> read_submission_bytes(const std::filesystem::path& file, const SubmissionLimits& limits,
                                                 Issues& issues) {
  return read_bounded_text(file, limits.max_file_bytes, issues);
}

std::optional<nlohmann::json> read_submission(const std::filesystem::path& file, const SubmissionLimits& limits,
                                              Issues& issues) {
  const std::optional<std::string> text = read_submission_bytes(file, limits, issues);
  if (!text) return std::nullopt;
  return parse_submission_text(*text, file.string(), limits, issues);
}

std::optional<nlohmann::json> parse_submission_text(const std::string& text, const std::string& label,
                                                    const SubmissionLimits& limits, Issues& issues) {
  if (static_cast<int64_t>(text.size()) > limits.max_file_bytes) {
    issues.error(
        "submission.size", label,
        size_problem(limits.max_file_bytes, strprintf("%.1f MiB", static_cast<double>(text.size()) / (1 << 20))));
    return std::nullopt;
  }
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) {
    issues.error(
        "submission.json", label,
        text.empty() ? "a JSON document, got an empty file (0 bytes)" : "a JSON document, got only whitespace");
    return std::nullopt;
  }
  CountingSax sax(limits);
  nlohmann::json::sax_parse(text, &sax);
  if (!sax.problem.empty()) {
    issues.error(sax.problem_check, label, sax.problem);
    return std::nullopt;
  }
  try {
    return parse_json_strict(text, label, "", limits.max_depth);
  } catch (const ParseError& e) {  // a key repeated in one object
    issues.error("submission.json", label + (e.record().empty() ? "" : ": " + e.record()), e.expected());
    return std::nullopt;
  }
}

std::vector<std::string> dataset_split_keys(const std::filesystem::path& dataset, const std::string& split) {
  const io::Dataset ds = io::Dataset::open(dataset);
  ds.require_split(split);
  std::vector<std::string> keys;
  for (const io::ShardEntry& shard : ds.shards(split)) {
    const std::string &first = shard.first_key, &last = shard.last_key;
    const int64_t tiles = shard.tiles;
    // Keys end in 6 digits; a shard whose range holds exactly `tiles` keys needs no reading.
    const auto number = [](const std::string& key) -> int64_t {
      if (key.size() < 7 || key[key.size() - 7] != '-') return -1;
      int64_t n = 0;
      for (size_t i = key.size() - 6; i < key.size(); ++i) {
        if (key[i] < '0' || key[i] > '9') return -1;
        n = n * 10 + (key[i] - '0');
      }
      return n;
    };
    const int64_t a = number(first), b = number(last);
    if (a >= 0 && b >= a && b - a + 1 == tiles &&
        first.substr(0, first.size() - 6) == last.substr(0, last.size() - 6)) {
      for (int64_t n = a; n <= b; ++n)
        keys.push_back(first.substr(0, first.size() - 6) + strprintf("%06lld", static_cast<long long>(n)));
      continue;
    }
    for (const io::DatasetTile& t : ds.read_shard(shard)) keys.push_back(t.key);
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

SubmissionReport validate_submission(const SubmissionValidateOptions& o) {
  o.validate();
  SubmissionReport report;
  report.issues.limit_per_check(kMaxListedIssues);
  const std::filesystem::path schemas = find_schemas_dir(o.schemas_dir);
  const std::optional<nlohmann::json> doc = read_submission(o.submission, o.limits, report.issues);
  if (!doc) return report;
  report.parsed = true;
  const std::string label = o.submission.string();
  report.issues.append(validate_against_schema(schema_path("submission", schemas), *doc, label, "submission.schema"));
  report.issues.append(check_submission_structure(*doc, label, o.limits));
  const bool has_tiles = doc->is_object() && doc->contains("tiles") && (*doc)["tiles"].is_object();
  if (has_tiles) report.tiles = static_cast<int64_t>((*doc)["tiles"].size());
  if (o.dataset.empty() || !has_tiles) return report;
  const std::vector<std::string> keys = dataset_split_keys(o.dataset, o.split);
  std::set<std::string> known(keys.begin(), keys.end());
  // An observation ladder's rung tiles (<key>-r<k>) are predicted and scored per rung; a
  // submission need not hold them, so they are never missing.
  const io::Dataset ds = io::Dataset::open(o.dataset);
  for (int rung : ds.rungs())
    if (!ds.rung_shards(o.split, rung).empty())
      for (const std::string& key : keys) known.insert(key + "-r" + std::to_string(rung));
  for (const auto& [key, tile] : (*doc)["tiles"].items())
    if (!known.count(key))
      report.issues.error(
          "submission.keys", label + ":/tiles/" + json_pointer_token(key),
          "a tile key of split '" + o.split + "' of the dataset, or of one of its ladder rungs (unknown key)");
  for (const std::string& key : keys)
    if (!(*doc)["tiles"].contains(key)) {
      report.missing_keys.push_back(key);
      report.issues.warning("submission.missing", label + ":/tiles/" + json_pointer_token(key),
                            "no prediction: scored as an empty graph");
    }
  return report;
}

}  // namespace nsg::validate
