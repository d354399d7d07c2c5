// `nsgraph validate`: schemas and named structural checks of a dataset, or of a
// submission against a dataset split. Exit 0 clean, 1 problems, 2 unreadable.
#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "limit_flags.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/strings.h"
#include "nsg/validate/documents.h"
#include "nsg/validate/dataset.h"
#include "nsg/validate/submission.h"

namespace nsg::cli {
namespace {

struct ValidateCliOptions {
  std::string dataset_positional;  // DATASET
  std::string submission;          // --submission FILE
  std::string dataset;             // --dataset DATASET (with --submission)
  std::string split = "test";
  std::string checks = "*";
  std::string schemas;
  bool list_checks = false;
  bool list_documents = false;
  bool json = false;
  validate::SubmissionLimits limits;

  void validate() const {
    if (list_checks || list_documents) return;
    if (submission.empty()) {
      NSG_CHECK(!dataset_positional.empty() || !dataset.empty(), ConfigError, "", "DATASET",
                "a dataset folder, or --submission FILE --dataset DATASET");
    } else {
      NSG_CHECK(dataset_positional.empty(), ConfigError, "", "DATASET",
                "no positional dataset with --submission (use --dataset)");
    }
  }
};

nlohmann::ordered_json issues_json(const Issues& issues) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const Issue& i : issues.items())
    out.push_back(
        {{"severity", severity_name(i.severity)}, {"check", i.check}, {"subject", i.subject}, {"message", i.message}});
  return out;
}

std::string summary(const Issues& issues, const std::string& what) {
  return strprintf("%zu error(s), %zu warning(s) in %s", issues.count(Severity::kError),
                   issues.count(Severity::kWarning), what.c_str());
}

int finish(const Issues& issues, const std::string& what, const ValidateCliOptions& o, nlohmann::ordered_json doc) {
  if (o.json) {
    doc["issues"] = issues_json(issues);
    doc["summary"] = {{"errors", issues.count(Severity::kError)},
                      {"warnings", issues.count(Severity::kWarning)},
                      {"valid", issues.count(Severity::kError) == 0}};
    std::cout << doc.dump(1) << "\n";
  } else {
    std::fputs(issues.format().c_str(), stdout);
    std::cout << summary(issues, what) << "\n";
  }
  return issues.count(Severity::kError) == 0 ? kExitOk : kExitProblems;
}

int run_validate(const ValidateCliOptions& o) {
  o.validate();
  if (o.list_documents) {
    std::cout << validate::documents_text();
    return kExitOk;
  }
  if (o.list_checks) {
    for (const validate::CheckInfo& c : validate::dataset_checks())
      if (validate::check_selected(o.checks, c.name)) std::cout << c.name << "\t" << c.description << "\n";
    return kExitOk;
  }
  if (!o.submission.empty()) {
    validate::SubmissionValidateOptions so;
    so.submission = o.submission;
    so.dataset = o.dataset;
    so.split = o.split;
    so.schemas_dir = o.schemas;
    so.limits = o.limits;
    const validate::SubmissionReport r = validate::validate_submission(so);
    nlohmann::ordered_json doc = {{"schema_version", "1"},         {"kind", "submission"}, {"submission", o.submission},
                                  {"dataset", o.dataset},          {"split", o.split},     {"tiles", r.tiles},
                                  {"missing_keys", r.missing_keys}};
    const std::string counts =
        r.parsed ? strprintf(" (%lld tiles, %zu missing)", static_cast<long long>(r.tiles), r.missing_keys.size())
                 : std::string(" (not parsed)");
    return finish(r.issues, "submission " + o.submission + counts, o, doc);
  }
  validate::DatasetValidateOptions dopt;
  dopt.progress = true;
  dopt.root = o.dataset_positional.empty() ? o.dataset : o.dataset_positional;
  dopt.schemas_dir = o.schemas;
  dopt.checks = o.checks;
  const Issues issues = validate::validate_dataset(dopt);
  nlohmann::ordered_json checks = nlohmann::ordered_json::array();
  for (const validate::CheckInfo& c : validate::dataset_checks())
    if (validate::check_selected(o.checks, c.name)) checks.push_back(c.name);
  nlohmann::ordered_json doc = {
      {"schema_version", "1"}, {"kind", "dataset"}, {"dataset", dopt.root.string()}, {"checks", checks}};
  return finish(issues, "dataset " + dopt.root.string() + strprintf(" (%zu checks)", checks.size()), o, doc);
}

}  // namespace

void add_validate_command(CLI::App& root, Context& ctx) {
  auto o = std::make_shared<ValidateCliOptions>();
  CLI::App* cmd = root.add_subcommand("validate", "Check a dataset (schemas and named checks) or a submission");
  cmd->add_option("DATASET", o->dataset_positional, "Dataset folder (holding manifest.json)");
  cmd->add_option("--submission", o->submission, "Submission JSON to check against --dataset");
  cmd->add_option("--dataset", o->dataset, "Dataset whose split keys a submission must use");
  cmd->add_option("--split", o->split, "Split a submission predicts")->capture_default_str();
  cmd->add_option("--checks", o->checks, "Comma-separated wildcards of checks to run (e.g. 'graph.*,shard.sha256')")
      ->capture_default_str();
  cmd->add_flag("--list-checks", o->list_checks, "List the dataset checks and exit");
  cmd->add_flag("--list-documents", o->list_documents,
                "List the documents nsgraph reads and writes (name, schema, reader, fuzz target, where) and exit");
  cmd->add_flag("--json", o->json, "Print a JSON report instead of lines");
  cmd->add_option("--schemas", o->schemas, "Folder holding v1/*.schema.json (default: installed or source tree)");
  add_submission_limit_flags(cmd, o->limits);
  cmd->footer(submission_limits_footer(o->limits));
  cmd->callback([o, &ctx]() { ctx.run = [o]() { return run_validate(*o); }; });
}

}  // namespace nsg::cli
