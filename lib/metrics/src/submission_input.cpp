#include "nsg/metrics/submission_input.h"

#include "nsg/metrics/io.h"
#include "nsg/validate/schema.h"

namespace nsg::metrics {

CheckedSubmission check_submission_document(const nlohmann::json& doc, const std::string& label,
                                            const std::filesystem::path& schemas_dir,
                                            const validate::SubmissionLimits& limits) {
  CheckedSubmission out;
  const std::filesystem::path dir = validate::find_schemas_dir(schemas_dir);
  out.issues =
      validate::validate_against_schema(dir / "v1" / "submission.schema.json", doc, label, "submission.schema");
  out.issues.append(validate::check_submission_structure(doc, label, limits));
  if (out.issues.empty()) out.graphs = graphs_from_submission(doc, label);
  return out;
}

CheckedSubmission check_submission_text(const std::string& text, const std::string& label,
                                        const std::filesystem::path& schemas_dir,
                                        const validate::SubmissionLimits& limits) {
  CheckedSubmission out;
  const std::optional<nlohmann::json> doc = validate::parse_submission_text(text, label, limits, out.issues);
  if (!doc) return out;
  return check_submission_document(*doc, label, schemas_dir, limits);
}

CheckedSubmission check_submission_file(const std::filesystem::path& file, const std::filesystem::path& schemas_dir,
                                        const validate::SubmissionLimits& limits) {
  // Read within the limits (file size, JSON values, nesting) before a DOM is built: a
  // huge or hostile file is refused, never parsed.
  CheckedSubmission out;
  const std::optional<nlohmann::json> doc = read_submission_file(file, limits, out.issues);
  if (!doc) return out;
  return check_submission_document(*doc, file.string(), schemas_dir, limits);
}

}  // namespace nsg::metrics
