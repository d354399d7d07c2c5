#include "nsg/metrics/receipt.h"

#include <cmath>
#include <functional>

#include "nsg/core/build_info.h"
#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "nsg/core/strings.h"
#include "nsg/core/version.h"

namespace nsg::metrics {

namespace {

using nlohmann::json;

// Aggregate values of a recomputed report may differ from the recorded ones by this much
// (relative to the larger magnitude, at least 1) and still be the same score.
constexpr double kAggregateTolerance = 1e-9;

// The report members the results digest covers; provenance labels (paths) are left out:
// they name files on the machine that scored, not what was scored.
constexpr const char* kResultMembers[] = {"params", "missing_tiles", "extra_tiles", "tiles", "aggregate"};

json limits_json(const validate::SubmissionLimits& l) {
  return {{"max_nodes_per_tile", l.max_nodes_per_tile},
          {"max_edges_per_tile", l.max_edges_per_tile},
          {"max_edge_length_px_per_tile", l.max_edge_length_px_per_tile},
          {"max_path_work_per_tile", l.max_path_work_per_tile},
          {"max_search_work_per_tile", l.max_search_work_per_tile},
          {"max_abs_coordinate_px", l.max_abs_coordinate_px},
          {"max_file_bytes", l.max_file_bytes},
          {"max_json_values", l.max_json_values},
          {"max_depth", l.max_depth}};
}

// The receipt fields that must agree; a different toolkit build is only a note (the
// results digest below says whether the numbers moved).
struct ComparedField {
  const char* pointer;
  const char* what;
  bool note;
};
constexpr ComparedField kComparedFields[] = {
    {"/ground_truth/kind", "ground truth kind", false},
    {"/ground_truth/manifest_sha256", "dataset manifest sha256", false},
    {"/ground_truth/sha256", "ground-truth file sha256", false},
    {"/ground_truth/split", "split", false},
    {"/ground_truth/verification", "ground-truth verification", true},
    {"/submission/sha256", "submission sha256", false},
    {"/submission/bytes", "submission bytes", false},
    {"/metrics_version", "metrics version", false},
    {"/limits", "limits", true},
    {"/options", "options", false},
    {"/toolkit/version", "toolkit version", true},
    {"/toolkit/git_commit", "toolkit commit", true},
};

const json& field(const json& object, const char* name, const std::string& file, const std::string& path,
                  bool (json::*is_type)() const noexcept, const char* type) {
  NSG_CHECK(object.is_object() && object.contains(name) && (object[name].*is_type)(), ParseError, file,
            path + "/" + name, type);
  return object[name];
}

int64_t integer_field(const json& object, const char* name, const std::string& file, const std::string& path) {
  return field(object, name, file, path, &json::is_number_integer, "an integer").get<int64_t>();
}

validate::SubmissionLimits limits_from(const json& j, const std::string& file) {
  const std::string path = "/receipt/limits";
  validate::SubmissionLimits l;
  l.max_nodes_per_tile = integer_field(j, "max_nodes_per_tile", file, path);
  l.max_edges_per_tile = integer_field(j, "max_edges_per_tile", file, path);
  l.max_edge_length_px_per_tile =
      field(j, "max_edge_length_px_per_tile", file, path, &json::is_number, "a number").get<double>();
  l.max_path_work_per_tile = integer_field(j, "max_path_work_per_tile", file, path);
  l.max_search_work_per_tile = integer_field(j, "max_search_work_per_tile", file, path);
  l.max_abs_coordinate_px = field(j, "max_abs_coordinate_px", file, path, &json::is_number, "a number").get<double>();
  l.max_file_bytes = integer_field(j, "max_file_bytes", file, path);
  l.max_json_values = integer_field(j, "max_json_values", file, path);
  const int64_t depth = integer_field(j, "max_depth", file, path);
  NSG_CHECK(depth > 0 && depth <= 64, ConfigError, file, path + "/max_depth", "a nesting depth in 1 … 64");
  l.max_depth = static_cast<int>(depth);
  l.validate();
  return l;
}

std::string text_at(const json& j, const std::string& pointer) {
  const json::json_pointer p(pointer);
  if (!j.contains(p)) return "(absent)";
  return j.at(p).is_string() ? j.at(p).get<std::string>() : j.at(p).dump();
}

// Every numeric leaf of two documents (aggregates, per-tile rows) agrees within the tolerance (and every other leaf
// exactly); the first that does not is described in `why`.
bool aggregates_agree(const json& a, const json& b, const std::string& path, std::string* why) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    if (std::fabs(x - y) <= kAggregateTolerance * std::max({1.0, std::fabs(x), std::fabs(y)})) return true;
    *why = path + ": recorded " + a.dump() + ", recomputed " + b.dump();
    return false;
  }
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) {
      *why = path + ": " + std::to_string(a.size()) + " entries recorded, " + std::to_string(b.size()) + " recomputed";
      return false;
    }
    for (size_t i = 0; i < a.size(); ++i)
      if (!aggregates_agree(a[i], b[i], path + "/" + std::to_string(i), why)) return false;
    return true;
  }
  if (a.is_object() && b.is_object()) {
    if (a.size() != b.size()) {
      *why = path + ": other members";
      return false;
    }
    for (const auto& [k, v] : a.items()) {
      if (!b.contains(k)) {
        *why = path + "/" + k + ": absent from the recomputed report";
        return false;
      }
      if (!aggregates_agree(v, b[k], path + "/" + k, why)) return false;
    }
    return true;
  }
  if (a != b) {
    *why = path + ": recorded " + a.dump() + ", recomputed " + b.dump();
    return false;
  }
  return true;
}

}  // namespace

std::string results_sha256(const json& report) {
  json results = json::object();
  for (const char* name : kResultMembers)
    if (report.is_object() && report.contains(name)) results[name] = report[name];
  return sha256_hex(results.dump());
}

json make_receipt(const ScoreReport& report, const ReceiptInputs& in, const validate::SubmissionLimits& limits) {
  json ground_truth = {{"kind", in.ground_truth_kind}};
  ground_truth[in.ground_truth_kind == "dataset" ? "manifest_sha256" : "sha256"] = in.ground_truth_sha256;
  if (in.ground_truth_kind == "dataset") ground_truth["split"] = in.split;
  ground_truth["verification"] = in.verification;
  return {{"schema_version", "1"},
          {"ground_truth", ground_truth},
          {"submission", {{"sha256", in.submission_sha256}, {"bytes", in.submission_bytes}}},
          {"toolkit", {{"name", "nsgraph"}, {"version", kVersion}, {"git_commit", git_commit()}}},
          {"metrics_version", kMetricsVersion},
          {"limits", limits_json(limits)},
          {"options",
           {{"params", report.params.to_json()}, {"split", in.split}, {"verify_ground_truth", in.verify_ground_truth}}},
          {"results_sha256", results_sha256(report_to_json(report))}};
}

const json& receipt_of(const json& doc, const std::string& file) {
  NSG_CHECK(doc.is_object(), ParseError, file, "", "a score report or a receipt (a JSON object)");
  if (doc.contains("receipt")) {
    NSG_CHECK(doc["receipt"].is_object(), ParseError, file, "/receipt", "an object");
    return doc["receipt"];
  }
  NSG_CHECK(doc.contains("results_sha256"), ParseError, file, "/receipt",
            "a score report with a receipt (written by nsgraph score), or a receipt");
  return doc;
}

std::string Receipt::ground_truth_identity() const {
  return ground_truth_kind + " " + ground_truth_sha256 + " " + split + " metrics v" + metrics_version;
}

namespace {

std::string string_field(const json& object, const char* name, const std::string& file, const std::string& path) {
  return field(object, name, file, path, &json::is_string, "a string").get<std::string>();
}

// One of `allowed`, or ParseError naming the field and the choices.
std::string choice_field(const json& object, const char* name, const std::string& file, const std::string& path,
                         std::initializer_list<const char*> allowed) {
  const std::string value = string_field(object, name, file, path);
  std::string choices;
  for (const char* a : allowed) {
    if (value == a) return value;
    choices += (choices.empty() ? "" : ", ") + std::string(a);
  }
  throw ParseError(file, path + "/" + name, "one of " + choices + ", got '" + printable_text(value) + "'");
}

// A lowercase hex sha256, as every digest the receipt records.
std::string digest_field(const json& object, const char* name, const std::string& file, const std::string& path) {
  const std::string value = string_field(object, name, file, path);
  const bool hex = value.size() == 64 && value.find_first_not_of("0123456789abcdef") == std::string::npos;
  NSG_CHECK(hex, ParseError, file, path + "/" + name, "a sha256: 64 lowercase hex digits");
  return value;
}

void read_ground_truth(const json& r, const std::string& file, Receipt& out) {
  const std::string at = "/receipt/ground_truth";
  const json& gt = field(r, "ground_truth", file, "/receipt", &json::is_object, "an object");
  out.ground_truth_kind = choice_field(gt, "kind", file, at, {"dataset", "file", "memory"});
  const bool dataset = out.ground_truth_kind == "dataset";
  out.ground_truth_sha256 = digest_field(gt, dataset ? "manifest_sha256" : "sha256", file, at);
  if (dataset) out.split = string_field(gt, "split", file, at);
  out.verification = choice_field(gt, "verification", file, at, {"sha256", "sizes", "file", "memory"});
}

void read_options(const json& r, const std::string& file, Receipt& out) {
  const std::string at = "/receipt/options";
  const json& options = field(r, "options", file, "/receipt", &json::is_object, "an object");
  // MetricParams::from_json checks names, types and the documented ranges.
  out.params = MetricParams::from_json(field(options, "params", file, at, &json::is_object, "an object"),
                                       file + ":" + at + "/params");
  out.options_split = string_field(options, "split", file, at);
  out.verify_ground_truth =
      field(options, "verify_ground_truth", file, at, &json::is_boolean, "true or false").get<bool>();
}

}  // namespace

Receipt read_receipt(const json& doc, const std::string& file) {
  const json& r = receipt_of(doc, file);
  NSG_CHECK(r.value("schema_version", json()) == "1", ParseError, file, "/receipt/schema_version", "\"1\"");
  Receipt out;
  read_ground_truth(r, file, out);
  const json& submission = field(r, "submission", file, "/receipt", &json::is_object, "an object");
  out.submission_sha256 = digest_field(submission, "sha256", file, "/receipt/submission");
  out.submission_bytes = integer_field(submission, "bytes", file, "/receipt/submission");
  NSG_CHECK(out.submission_bytes >= 0, ParseError, file, "/receipt/submission/bytes", "a size >= 0");
  const json& toolkit = field(r, "toolkit", file, "/receipt", &json::is_object, "an object");
  NSG_CHECK(string_field(toolkit, "name", file, "/receipt/toolkit") == "nsgraph", ParseError, file,
            "/receipt/toolkit/name", "\"nsgraph\"");
  out.toolkit_version = string_field(toolkit, "version", file, "/receipt/toolkit");
  out.toolkit_commit = string_field(toolkit, "git_commit", file, "/receipt/toolkit");
  out.metrics_version = string_field(r, "metrics_version", file, "/receipt");
  out.limits = limits_from(field(r, "limits", file, "/receipt", &json::is_object, "an object"), file);
  read_options(r, file, out);
  out.results_sha256 = digest_field(r, "results_sha256", file, "/receipt");
  return out;
}

ReceiptComparison compare_receipt(const json& recorded, const json& recomputed, const std::string& file) {
  const json& a = receipt_of(recorded, file);
  const json& b = receipt_of(recomputed, "(recomputed)");
  ReceiptComparison out;
  for (const ComparedField& f : kComparedFields) {
    const std::string x = text_at(a, f.pointer), y = text_at(b, f.pointer);
    if (x != y)
      (f.note ? out.notes : out.differences).push_back(std::string(f.what) + ": recorded " + x + ", recomputed " + y);
  }

  const std::string recorded_results = text_at(a, "/results_sha256");
  const bool whole_report = recorded.contains("aggregate");
  // A report whose numbers were changed after scoring no longer hashes to its receipt.
  if (whole_report && results_sha256(recorded) != recorded_results)
    out.differences.push_back("the report's numbers do not hash to its receipt's results_sha256 " + recorded_results +
                              " (changed after scoring)");
  if (recorded_results != text_at(b, "/results_sha256")) {
    std::string why;
    if (!whole_report)
      out.differences.push_back("results sha256: recorded " + recorded_results + ", recomputed " +
                                text_at(b, "/results_sha256") + " (give the whole report to compare the values)");
    else if (!aggregates_agree(recorded.value("tiles", json()), recomputed.at("tiles"), "/tiles", &why) ||
             !aggregates_agree(recorded["aggregate"], recomputed.at("aggregate"), "/aggregate", &why))
      out.differences.push_back("results: " + why);
    else
      out.notes.push_back(
          strprintf("the values differ in their last bits; every per-tile and aggregate value agrees "
                    "within %g (another CPU or compiler)",
                    kAggregateTolerance));
  }
  return out;
}

}  // namespace nsg::metrics
