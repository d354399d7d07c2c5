#include "nsg/validate/schema.h"

#include <algorithm>

// GCC 12 reports a false -Wrestrict inside valijson's json_pointer.hpp.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>
#pragma GCC diagnostic pop

#include "nsg/core/error.h"
#include "nsg/core/files.h"

namespace fs = std::filesystem;

namespace nsg::validate {
namespace {

// valijson contexts look like ["<root>", "[tiles]", "[key]", "[3]"]: make a JSON pointer.
std::string to_pointer(const std::vector<std::string>& context) {
  std::string out;
  for (const std::string& part : context) {
    if (part == "<root>") continue;
    std::string token = part;
    if (token.size() >= 2 && token.front() == '[' && token.back() == ']') token = token.substr(1, token.size() - 2);
    if (token.size() >= 2 && token.front() == '"' && token.back() == '"') token = token.substr(1, token.size() - 2);
    out += "/" + token;
  }
  return out.empty() ? "/" : out;
}

}  // namespace

struct SchemaValidator::Impl {
  valijson::Schema schema;
};

SchemaValidator::SchemaValidator(const fs::path& schema_path) : impl_(std::make_shared<Impl>()) {
  nlohmann::json schema_doc;
  try {
    schema_doc = nlohmann::json::parse(read_file(schema_path));
  } catch (const nlohmann::json::parse_error& e) {
    throw ParseError(schema_path.string(), "", std::string("a JSON schema: ") + e.what());
  }
  valijson::SchemaParser parser;
  valijson::adapters::NlohmannJsonAdapter schema_adapter(schema_doc);
  try {
    parser.populateSchema(schema_adapter, impl_->schema);
  } catch (const std::exception& e) {
    throw ParseError(schema_path.string(), "", std::string("a valid draft-07 schema: ") + e.what());
  }
}

Issues SchemaValidator::validate(const nlohmann::json& doc, const std::string& file_label,
                                 const std::string& check) const {
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(doc);
  Issues issues;
  if (validator.validate(impl_->schema, target, &results)) return issues;
  // valijson also reports every enclosing value ("Failed to validate item #0"); keep
  // the innermost errors, which name the offending value. Paths sorted once, so a
  // wrapper's inner errors are one binary search away (hostile files bring 10^5 errors).
  std::vector<std::pair<std::string, std::string>> errors;
  valijson::ValidationResults::Error error;
  while (results.popError(error)) errors.push_back({to_pointer(error.context), error.description});
  std::vector<std::string> paths;
  paths.reserve(errors.size());
  for (const auto& e : errors) paths.push_back(e.first);
  std::sort(paths.begin(), paths.end());
  const auto has_inner_error = [&](const std::string& path) {
    if (path == "/") return paths.back() != "/";
    const std::string inner = path + "/";
    const auto it = std::lower_bound(paths.begin(), paths.end(), inner);
    return it != paths.end() && it->compare(0, inner.size(), inner) == 0;
  };
  issues.limit_per_check(kMaxListedIssues);
  for (const auto& [path, message] : errors) {
    // Wrappers ("Failed to validate item #0 …") repeat an inner error; real errors at an
    // enclosing path (e.g. an unknown property of the root) are kept.
    if (message.rfind("Failed to validate", 0) == 0 && has_inner_error(path)) continue;
    issues.error(check, file_label + ":" + path, message);
  }
  return issues;
}

Issues validate_against_schema(const fs::path& schema_path, const nlohmann::json& doc, const std::string& file_label,
                               const std::string& check) {
  return SchemaValidator(schema_path).validate(doc, file_label, check);
}

fs::path find_schemas_dir(const fs::path& override_dir) {
  if (!override_dir.empty()) {
    NSG_CHECK(fs::is_directory(override_dir), IoError, override_dir.string(), "",
              "a folder holding the v1/*.schema.json files");
    return override_dir;
  }
  std::vector<fs::path> tries;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    tries.push_back(exe.parent_path().parent_path().parent_path() / "schemas");
    tries.push_back(exe.parent_path().parent_path() / "share" / "nsgraph" / "schemas");
  }
#ifdef NSG_SCHEMAS_SOURCE_DIR
  tries.push_back(NSG_SCHEMAS_SOURCE_DIR);
#endif
  for (const fs::path& p : tries)
    if (fs::is_regular_file(p / "v1" / "submission.schema.json")) return p;
  throw IoError("schemas/", "",
                "the published schemas next to the executable or in the "
                "source tree (pass --schemas DIR)");
}

}  // namespace nsg::validate
