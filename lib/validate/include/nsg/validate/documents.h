#pragma once
// Every JSON document nsgraph writes or reads, declared once: its name, where it lives, the
// JSON Schema that describes it, the one reader that parses it (with the format's limits) and
// the libFuzzer target that feeds that reader hostile bytes. The schema lookup (schema_path),
// `nsgraph validate --list-documents`, the table in docs/schemas.md and the fuzz targets'
// list in scripts/fuzz.sh are held to it (tests/unit/validate/test_documents.cpp).
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace nsg::validate {

struct DocumentKind {
  std::string_view name;         // "manifest": what the table, errors and docs call it
  std::string_view where;        // "<dataset>/manifest.json"
  std::string_view schema;       // "manifest.schema.json" under schemas/v1/ ("" = none)
  std::string_view reader;       // "io::read_manifest": the one function that parses it
  std::string_view fuzz_target;  // "manifest" (fuzz/fuzz_manifest.cpp; "" = none)
  std::string_view written_by;   // "nsgraph generate"; "you" for a user's file
};

// The table, in the order docs/schemas.md lists it.
std::span<const DocumentKind> documents();
// The entry named `name`; InternalError for a name the table lacks (a typo in our code).
const DocumentKind& document(std::string_view name);
// The schema of document `name` in the published schemas (find_schemas_dir(schemas_dir)).
// InternalError when the document has no schema.
std::filesystem::path schema_path(std::string_view name, const std::filesystem::path& schemas_dir = {});
// The table as Markdown (docs/schemas.md) or tab-separated lines (`--list-documents`).
std::string documents_markdown();
std::string documents_text();

}  // namespace nsg::validate
