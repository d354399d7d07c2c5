// The labels files of `segment` (schemas/v1/segment-labels.schema.json): the shipped
// label sets load, the built-in lidarseg mapping equals the shipped file, and bad files
// are refused naming the file and the offending key.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "nsg/core/error.h"
#include "nsg/nuscenes/lidarseg.h"
#include "nsg/segment/labels.h"
#include "test_support.h"

namespace nsg::segment {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json_file(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

fs::path labels_dir() { return test::source_dir() / "samples" / "semantic-labels"; }

TEST(Labels, ClassNamesEqualTheSemanticClassesFile) {
  const nlohmann::json doc = read_json_file(test::source_dir() / "samples" / "semantic-classes.json");
  ASSERT_EQ(doc["classes"].size(), class_names().size());
  for (const auto& c : doc["classes"]) EXPECT_EQ(class_names().at(c["id"].get<size_t>()), c["name"].get<std::string>());
}

TEST(Labels, ShippedLabelSetsLoad) {
  const SegmentLabels cityscapes = load_labels(labels_dir() / "cityscapes.json");
  EXPECT_EQ(cityscapes.max_channel(), 18);  // 19 train ids
  ASSERT_TRUE(cityscapes.input.has_value());
  EXPECT_EQ(cityscapes.class_of(0), 0);    // road
  EXPECT_EQ(cityscapes.class_of(13), 8);   // car
  EXPECT_EQ(cityscapes.class_of(10), 13);  // sky
  const SegmentLabels vistas = load_labels(labels_dir() / "mapillary-vistas-v1.2.json");
  EXPECT_EQ(vistas.max_channel(), 65);  // 66 classes
  EXPECT_EQ(vistas.class_of(24), 1);    // Lane Marking - General → lane_marking
  EXPECT_EQ(vistas.class_of(65), kVoid);
  const SegmentLabels lidarseg = load_labels(labels_dir() / "nuscenes-lidarseg.json");
  EXPECT_EQ(lidarseg.max_channel(), nuscenes::kLidarsegClassCount - 1);
  EXPECT_FALSE(lidarseg.input.has_value());
}

TEST(Labels, ShippedFilesNameTheirSourceClassesInOrder) {
  // The lidarseg file's source_classes are the 32 category names by index.
  const nlohmann::json doc = read_json_file(labels_dir() / "nuscenes-lidarseg.json");
  for (int i = 0; i < nuscenes::kLidarsegClassCount; ++i)
    EXPECT_EQ(doc["source_classes"][std::to_string(i)], nuscenes::lidarseg_class_names()[static_cast<size_t>(i)]);
  EXPECT_EQ(read_json_file(labels_dir() / "cityscapes.json")["source_classes"]["18"], "bicycle");
  EXPECT_EQ(read_json_file(labels_dir() / "mapillary-vistas-v1.2.json")["source_classes"]["65"], "Unlabeled");
}

TEST(Labels, TheDocumentedExampleLoads) {
  const SegmentLabels l = labels_from_json(nlohmann::json::parse(R"({"schema_version": "1",
      "input": {"width": 800, "height": 448, "rgb": true, "scale": 0.00392156862745098,
                "mean": [0.485, 0.456, 0.406], "std": [0.229, 0.224, 0.225]},
      "classes": {"0": "road", "1": "sidewalk", "2": "building", "5": "pole_sign", "13": "car", "10": "void"}})"),
                                           "example.json");
  EXPECT_EQ(l.max_channel(), 13);
  EXPECT_EQ(l.class_of(13), 8);
  EXPECT_EQ(l.class_of(5), 12);
  EXPECT_EQ(l.class_of(10), kVoid);
  EXPECT_EQ(l.class_of(3), kVoid);  // unnamed
  ASSERT_TRUE(l.input.has_value());
  EXPECT_EQ(l.input->width, 800);
  EXPECT_DOUBLE_EQ(l.input->std[2], 0.225);
}

TEST(Labels, BuiltinLidarsegEqualsTheShippedFile) {
  const SegmentLabels shipped = load_labels(labels_dir() / "nuscenes-lidarseg.json");
  EXPECT_EQ(builtin_lidarseg_labels().class_of_channel, shipped.class_of_channel);
  EXPECT_EQ(builtin_lidarseg_labels().table()[24], 0);     // flat.driveable_surface → road
  EXPECT_EQ(builtin_lidarseg_labels().table()[0], kVoid);  // noise
  EXPECT_EQ(builtin_lidarseg_labels().table()[200], kVoid);
}

// Runs labels_from_json and returns the ParseError's message ("" if none).
std::string parse_error(const nlohmann::json& doc) {
  try {
    labels_from_json(doc, "bad-labels.json");
  } catch (const ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(Labels, UnknownClassNamesTheFileAndChannel) {
  const std::string e = parse_error({{"schema_version", "1"}, {"classes", {{"0", "road"}, {"3", "lamppost"}}}});
  EXPECT_NE(e.find("bad-labels.json"), std::string::npos) << e;
  EXPECT_NE(e.find("/classes/3"), std::string::npos) << e;
  EXPECT_NE(e.find("lamppost"), std::string::npos) << e;
}

TEST(Labels, SchemaViolationsNameTheFile) {
  EXPECT_NE(parse_error({{"schema_version", "1"}}).find("bad-labels.json"), std::string::npos);  // no classes
  EXPECT_NE(parse_error({{"schema_version", "1"}, {"classes", {{"x1", "road"}}}}), "");          // not a channel
  EXPECT_NE(parse_error({{"schema_version", "1"}, {"classes", {{"0", "road"}}}, {"input", {{"width", 8}}}}), "");
  EXPECT_EQ(parse_error({{"schema_version", "1"}, {"classes", {{"0", "road"}, {"7", "void"}}}}), "");
}

TEST(Labels, NotJsonNamesTheFile) {
  test::TempDir dir("labels");
  test::write_text(dir / "labels.json", "{not json");
  try {
    load_labels(dir / "labels.json");
    FAIL() << "accepted";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("labels.json"), std::string::npos);
    EXPECT_EQ(e.exit_code(), kExitInput);
  }
}

}  // namespace
}  // namespace nsg::segment

namespace nsg::segment {
namespace {

// A channel named twice would silently keep its last class: the file is refused by name.
TEST(Labels, RepeatedChannelInAFileIsRefused) {
  nsg::test::TempDir dir("labels-dup");
  const std::filesystem::path file = dir / "dup.json";
  nsg::test::write_text(file, R"({"schema_version": "1", "classes": {"0": "road", "0": "car"}})");
  try {
    load_labels(file);
    ADD_FAILURE() << "a repeated channel was accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_NE(std::string(e.what()).find("\"0\""), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nsg::segment
