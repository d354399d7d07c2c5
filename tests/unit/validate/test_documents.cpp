// The declared table of documents (validate/documents.h) against what ships: every schema in
// schemas/v1 is one document's, every fuzz target it names exists and runs in `make fuzz`,
// docs/schemas.md carries the table as the code prints it, and the CLI lists it.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/validate/documents.h"
#include "test_support.h"

namespace nsg::validate {
namespace {

namespace fs = std::filesystem;

TEST(Documents, EverySchemaBelongsToOneDocumentAndIsFound) {
  std::set<std::string> declared;
  for (const DocumentKind& d : documents()) {
    if (d.schema.empty()) continue;
    EXPECT_TRUE(declared.insert(std::string(d.schema)).second) << d.schema << " declared twice";
    EXPECT_TRUE(fs::is_regular_file(schema_path(d.name, test::source_dir() / "schemas"))) << d.name;
  }
  std::set<std::string> shipped;
  for (const auto& e : fs::directory_iterator(test::source_dir() / "schemas" / "v1"))
    shipped.insert(e.path().filename().string());
  EXPECT_EQ(declared, shipped);
  EXPECT_THROW(document("no-such-document"), InternalError);
  EXPECT_THROW(schema_path("frames-results"), InternalError);  // a document without a schema
}

TEST(Documents, EveryFuzzTargetIsBuiltAndRunByMakeFuzz) {
  const std::string script = read_file(test::source_dir() / "scripts" / "fuzz.sh");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(script, m, std::regex(R"re(FUZZ_TARGETS:-"([^"]*)")re")));
  const std::string targets = " " + m[1].str() + " ";
  const std::string cmake = read_file(test::source_dir() / "fuzz" / "CMakeLists.txt");
  for (const DocumentKind& d : documents()) {
    if (d.fuzz_target.empty()) continue;
    const std::string t(d.fuzz_target);
    EXPECT_TRUE(fs::is_regular_file(test::source_dir() / "fuzz" / ("fuzz_" + t + ".cpp"))) << t;
    EXPECT_NE(cmake.find("nsg_add_fuzzer(" + t + " "), std::string::npos) << t;
    EXPECT_NE(targets.find(" " + t + " "), std::string::npos) << t << " is not in scripts/fuzz.sh FUZZ_TARGETS";
  }
}

TEST(Documents, TheDocsCarryTheTableAndTheCliListsIt) {
  const std::string doc = read_file(test::source_dir() / "docs" / "schemas.md");
  EXPECT_NE(doc.find(documents_markdown()), std::string::npos)
      << "docs/schemas.md: the documents table differs from validate/documents.cpp; it should read\n"
      << documents_markdown();
  const test::CommandResult r = test::run_nsgraph({"validate", "--list-documents"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, documents_text());
}

}  // namespace
}  // namespace nsg::validate
