// Model files are outside input: a forest's tree structure and a gzip's inflated size are
// checked before OpenCV sees them (a tree cut before its leaves once hung loading; a 4 MiB
// .yml.gz inflating to 4 GiB ran out of memory).
#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/core/files.h"
#include "nsg/model/model.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using nsg::test::run_program;

// The committed b1 model as YAML text.
std::string golden_yaml() {
  const fs::path gz = nsg::test::data_dir() / "golden/model/b1-e2e-trees2.yml.gz";
  const auto r = run_program({"gzip", "-dc", gz.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.out;
}

// What loading `text` as a model file refuses, by record ("" when it loads).
std::string refused_record(const fs::path& dir, const std::string& text) {
  const fs::path file = dir / "m.yml";
  nsg::test::write_text(file, text);
  try {
    nsg::model::LaneModel::load(file);
    return "";
  } catch (const nsg::ParseError& e) {
    EXPECT_EQ(e.file(), file.string());
    return e.record();
  }
}

TEST(HostileModel, TreeStructureIsCheckedBeforeOpenCv) {
  nsg::test::TempDir dir("hostile-model");
  const std::string yaml = golden_yaml();
  ASSERT_EQ(refused_record(dir.path(), yaml), "");
  // The first tree cut after its root (a split with no subtrees).
  const size_t root = yaml.find("         nodes:\n");
  ASSERT_NE(root, std::string::npos);
  const size_t second = yaml.find("            -\n               depth: 1", root);
  const size_t next_tree = yaml.find("      -\n         nodes:\n", second);
  ASSERT_NE(second, std::string::npos);
  ASSERT_NE(next_tree, std::string::npos);
  std::string cut = yaml;
  cut.erase(second, next_tree - second);
  EXPECT_EQ(refused_record(dir.path(), cut), "centre/trees/0/nodes");
  // A split on a variable the model does not have.
  std::string var = yaml;
  const size_t v = var.find("{ var:", root);
  var.replace(v, 6, "{ var:99999");
  const std::string record = refused_record(dir.path(), var);
  EXPECT_NE(record.find("/splits/0/var"), std::string::npos) << record;
  // Nodes out of preorder.
  std::string depth = yaml;
  depth.replace(depth.find("depth: 1", root), 8, "depth: 7");
  EXPECT_EQ(refused_record(dir.path(), depth), "centre/trees/0/nodes/1/depth");
}

// An integer option stored as a number beyond int (a cast of 1e308 to int is undefined
// behaviour: found by fuzz_model) or as text is refused by name.
TEST(HostileModel, IntegerOptionsOutsideTheirTypeAreRefusedByName) {
  nsg::test::TempDir dir("hostile-model-int");
  const std::string yaml = golden_yaml();
  const size_t at = yaml.find("   min_component_px: 20\n");
  ASSERT_NE(at, std::string::npos);
  for (const char* value : {"1.7976931348623157e+308", "-1e10", "\"20\""}) {
    std::string edited = yaml;
    edited.replace(at, std::string("   min_component_px: 20").size(), std::string("   min_component_px: ") + value);
    EXPECT_EQ(refused_record(dir.path(), edited), "extraction/min_component_px") << value;
  }
}

TEST(HostileModel, GzipBombIsStoppedAtTheLimit) {
  nsg::test::TempDir dir("hostile-model-gz");
  const fs::path bomb = dir / "bomb.yml.gz";
  const auto r = run_program({"sh", "-c", "head -c 300000000 /dev/zero | gzip -1 > '" + bomb.string() + "'"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_LT(fs::file_size(bomb), 2u << 20);
  try {
    nsg::model::LaneModel::load(bomb);
    ADD_FAILURE() << "a 300 MB inflation loaded";
  } catch (const nsg::ParseError& e) {
    EXPECT_EQ(e.record(), "gzip");
    EXPECT_NE(std::string(e.what()).find("at most 256 MiB"), std::string::npos) << e.what();
  }
}

}  // namespace
