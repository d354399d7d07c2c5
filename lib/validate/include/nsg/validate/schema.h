#pragma once
// JSON Schema (draft-07) validation with valijson, reported as Issues whose subject is
// "<file_label>:<JSON pointer>" so a user can find the offending value.
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "nsg/core/issues.h"

namespace nsg::validate {

// A parsed schema, reusable for many documents (parsing a schema costs more than using it).
class SchemaValidator {
 public:
  // Throws IoError/ParseError if the schema cannot be read or parsed.
  explicit SchemaValidator(const std::filesystem::path& schema_path);
  Issues validate(const nlohmann::json& doc, const std::string& file_label, const std::string& check) const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// Validates `doc` against the schema file. Throws IoError/ParseError if the schema itself
// cannot be read or parsed. Issues use check name `<check>` (e.g. "submission.schema").
Issues validate_against_schema(const std::filesystem::path& schema_path, const nlohmann::json& doc,
                               const std::string& file_label, const std::string& check);

// The published schemas: `override_dir` if not empty, else the first of
// <exe>/../../schemas, <exe>/../share/nsgraph/schemas, the source tree's schemas/.
std::filesystem::path find_schemas_dir(const std::filesystem::path& override_dir = {});

}  // namespace nsg::validate
