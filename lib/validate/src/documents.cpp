#include "nsg/validate/documents.h"

#include <array>

#include "nsg/core/error.h"
#include "nsg/validate/schema.h"

namespace nsg::validate {
namespace {

// clang-format off
constexpr std::array kDocuments = {
    DocumentKind{"manifest", "<dataset>/manifest.json", "manifest.schema.json",
                 "io::read_manifest", "manifest", "nsgraph generate, merge"},
    DocumentKind{"done-record", "<dataset>/parts/share-<i>-of-<n>.json", "done-record.schema.json",
                 "pipeline::read_done_record", "merge", "nsgraph generate (each share)"},
    DocumentKind{"tile-meta", "<key>.meta.json in a shard", "tile-meta.schema.json",
                 "io::tile_meta_from_json", "tile_json", "nsgraph generate"},
    DocumentKind{"tile-graph", "<key>.graph.json in a shard", "tile-graph.schema.json",
                 "io::tile_graph_from_json", "tile_json", "nsgraph generate"},
    DocumentKind{"submission", "a submission file", "submission.schema.json",
                 "validate::read_submission", "submission", "you (nsgraph predict)"},
    DocumentKind{"score-report", "report.json of nsgraph score (its receipt)", "score-report.schema.json",
                 "metrics::read_receipt", "receipt", "nsgraph score"},
    DocumentKind{"frames-manifest", "<export>/manifest.json", "frames-manifest.schema.json",
                 "metrics::read_frames_manifest", "frames_manifest", "nsgraph frames"},
    DocumentKind{"frame", "<export>/<split>/<scene>/info/<timestamp>.json", "frame.schema.json",
                 "metrics::read_frame_record", "frames_record", "nsgraph frames"},
    DocumentKind{"frames-results", "a frames submission (OpenLane-V2's results)", "",
                 "metrics::read_frames_results", "frames", "you (nsgraph predict --frames)"},
    DocumentKind{"synth-changes", "<release>/changes.json", "synth-changes.schema.json",
                 "synth::read_map_changes", "", "nsgraph synth (config changes)"},
    DocumentKind{"generate-config", "a generate config", "generate-config.schema.json",
                 "pipeline::resolve_generate_config", "", "you (samples/generate-*.json)"},
    DocumentKind{"synth-config", "a synth config", "synth-config.schema.json",
                 "synth::SynthConfig::from_file", "", "you (samples/synth/*.json)"},
    DocumentKind{"train-config", "a train config", "train-config.schema.json",
                 "model::resolve_train_config", "", "you (samples/train-*.json)"},
    DocumentKind{"frames-config", "a frames config", "frames-config.schema.json",
                 "frames::resolve_frames_config", "", "you"},
    DocumentKind{"graphify-config", "a graphify config", "graphify-config.schema.json",
                 "skeleton::resolve_graphify_config", "", "you"},
    DocumentKind{"segment-labels", "a segmentation model's labels file", "segment-labels.schema.json",
                 "segment::load_labels", "", "you (samples/semantic-labels/*.json)"},
};
// clang-format on

}  // namespace

std::span<const DocumentKind> documents() { return kDocuments; }

const DocumentKind& document(std::string_view name) {
  for (const DocumentKind& d : kDocuments)
    if (d.name == name) return d;
  throw InternalError("", std::string(name), "a document of the table in validate/documents.cpp");
}

std::filesystem::path schema_path(std::string_view name, const std::filesystem::path& schemas_dir) {
  const DocumentKind& d = document(name);
  if (d.schema.empty()) throw InternalError("", std::string(name), "a document with a schema");
  return find_schemas_dir(schemas_dir) / "v1" / std::string(d.schema);
}

std::string documents_markdown() {
  std::string out =
      "| document | where | schema | reader | fuzz target | written by |\n"
      "|---|---|---|---|---|---|\n";
  const auto cell = [](std::string_view v, bool code) {
    if (v.empty()) return std::string("—");
    return code ? "`" + std::string(v) + "`" : std::string(v);
  };
  for (const DocumentKind& d : kDocuments)
    out += "| " + std::string(d.name) + " | " + cell(d.where, d.where.starts_with("<")) + " | " + cell(d.schema, true) +
           " | " + cell(d.reader, true) + " | " + cell(d.fuzz_target, true) + " | " + cell(d.written_by, false) +
           " |\n";
  return out;
}

std::string documents_text() {
  std::string out;
  for (const DocumentKind& d : kDocuments)
    out += std::string(d.name) + "\t" + std::string(d.schema.empty() ? "-" : d.schema) + "\t" + std::string(d.reader) +
           "\t" + std::string(d.fuzz_target.empty() ? "-" : d.fuzz_target) + "\t" + std::string(d.where) + "\n";
  return out;
}

}  // namespace nsg::validate
