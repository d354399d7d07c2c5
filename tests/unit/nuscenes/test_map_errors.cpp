// Malformed map expansion files: each must raise the right exception type with a message
// naming the file, the record (layer and token) and what was expected.
#include <gtest/gtest.h>

#include <functional>

#include "nsg/core/error.h"
#include "nsg/nuscenes/map_expansion.h"
#include "test_map_fixture.h"

namespace nsg::nuscenes {
namespace {

using test::replace_after;
using test::replace_once;

// Loads `text` as boston-seaport.json; expects ErrorType whose message contains the file
// name and every string of `needles`.
template <class ErrorType>
void expect_load_error(const std::string& text, const std::vector<std::string>& needles) {
  test::TempDir root("map-bad");
  const auto file = test::write_map(root, text);
  try {
    (void)load_map_expansion_file(file);
    ADD_FAILURE() << "expected an exception for: " << ::testing::PrintToString(needles);
  } catch (const ErrorType& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), file.string());
    EXPECT_NE(what.find("boston-seaport.json"), std::string::npos) << what;
    for (const std::string& needle : needles) {
      EXPECT_NE(what.find(needle), std::string::npos) << "missing '" << needle << "' in: " << what;
    }
  } catch (const Error& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
  }
}

const std::string& fixture() {
  static const std::string text = test::small_map_text();
  return text;
}

TEST(MapErrors, TruncatedFile) {
  const size_t cut = fixture().find("\"lane_type\": \"CAR\"");
  ASSERT_NE(cut, std::string::npos);
  expect_load_error<ParseError>(fixture().substr(0, cut), {"'lane-a'", "ends early"});
}

TEST(MapErrors, TruncatedInsideAString) {
  const size_t cut = fixture().find("line-edge-b\"");
  expect_load_error<ParseError>(fixture().substr(0, cut), {"JSON"});
}

TEST(MapErrors, EmptyFileAndNotJson) {
  expect_load_error<ParseError>("", {"expected"});
  expect_load_error<ParseError>("[1, 2]", {"object"});
}

TEST(MapErrors, TrailingContent) { expect_load_error<ParseError>(fixture() + "{}", {"end of the file"}); }

TEST(MapErrors, WrongTypeNamesRecordAndKey) {
  expect_load_error<ParseError>(replace_after(fixture(), "\"token\": \"n3\"", "40.0", "\"40.0\""),
                                {"node 'n3'", "key \"x\"", "number"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"token\": \"rs-1\"", "false", "\"no\""),
                                {"road_segment 'rs-1'", "is_intersection", "true or false"});
  expect_load_error<ParseError>(replace_once(fixture(), "\"walkway\": [", "\"walkway\": {\"a\": ["),
                                {"walkway", "array"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"lane-a\": [", "\"radius\": 999.999", "\"radius\": [1]"),
                                {"arcline_path_3 'lane-a' path #0", "radius"});
}

TEST(MapErrors, MissingRecordKeyNamesRecord) {
  expect_load_error<ParseError>(
      replace_after(fixture(), "\"token\": \"lane-b\"", "\"polygon_token\"", "\"polygon_tokn\""),
      {"lane 'lane-b'", "polygon_token", "missing"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"conn-1\": {", "\"outgoing\"", "\"outgoin\""),
                                {"connectivity 'conn-1'", "outgoing", "missing"});
  expect_load_error<ParseError>(replace_once(fixture(), "\"token\": \"pc-1\"", "\"name\": \"pc-1\""),
                                {"ped_crossing #0", "token", "missing"});
}

TEST(MapErrors, MissingTopLevelKey) {
  expect_load_error<ParseError>(replace_once(fixture(), "\"carpark_area\": [", "\"carpark_areas\": ["),
                                {"carpark_area", "missing"});
  expect_load_error<ParseError>(replace_once(fixture(), "\"canvas_edge\"", "\"canvas\""), {"canvas_edge", "missing"});
}

TEST(MapErrors, OldVersionsRejectedByStringComparison) {
  expect_load_error<DataError>(replace_once(fixture(), "\"1.3\"", "\"1.2\""), {"\"1.2\"", "1.3"});
  expect_load_error<DataError>(replace_once(fixture(), "\"1.3\"", "\"1.10\""), {"\"1.10\""});
  expect_load_error<DataError>(replace_once(fixture(), "\"version\": \"1.3\",", ""), {"\"1.0\""});
  expect_load_error<ParseError>(replace_once(fixture(), "\"1.3\"", "1.3"), {"version", "string"});
}

TEST(MapErrors, DanglingPolygonLineNode) {
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"lane-a\"", "\"poly-lane-a\"", "\"poly-none\""),
                               {"lane 'lane-a'", "polygon_token", "'poly-none'", "dangling"});
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"da-1\"", "\"poly-conn\"", "\"poly-none\""),
                               {"drivable_area 'da-1'", "'poly-none'"});
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"tl-1\"", "\"line-tl\"", "\"line-none\""),
                               {"traffic_light 'tl-1'", "line_token", "'line-none'"});
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"line-div\"", "\"n3\"", "\"n99\""),
                               {"line 'line-div'", "node_tokens", "'n99'"});
  expect_load_error<DataError>(replace_after(fixture(), "\"node_tokens\": [", "\"h2\"", "\"h9\""),
                               {"polygon 'poly-road'", "holes", "'h9'"});
  expect_load_error<DataError>(replace_after(fixture(), "\"right_lane_divider_segments\"", "\"n2\"", "\"n77\""),
                               {"lane 'lane-a'", "right_lane_divider_segments", "'n77'"});
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"ld-1\"", "\"n4\"", "\"n77\""),
                               {"lane_divider 'ld-1'", "'n77'"});
}

TEST(MapErrors, DanglingStopLineCues) {
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"sl-light\"", "\"tl-1\"", "\"tl-9\""),
                               {"stop_line 'sl-light'", "traffic_light_tokens", "'tl-9'"});
  expect_load_error<DataError>(replace_after(fixture(), "\"token\": \"sl-ped\"", "\"pc-1\"", "\"pc-9\""),
                               {"stop_line 'sl-ped'", "ped_crossing_tokens", "'pc-9'"});
  // STOP_SIGN / YIELD cues are not resolved by the devkit: a dangling token is tolerated.
  test::TempDir root("map-cue");
  const std::string ok = replace_after(fixture(), "\"token\": \"sl-sign\"", "\"traffic_light_tokens\": []",
                                       "\"traffic_light_tokens\": [\"x\"]");
  EXPECT_NO_THROW(load_map_expansion_file(test::write_map(root, ok)));
}

TEST(MapErrors, NonFiniteNumbers) {
  expect_load_error<ParseError>(replace_after(fixture(), "\"token\": \"n2\"", "40.0", "NaN"),
                                {"node 'n2'", "key \"x\""});
  expect_load_error<ParseError>(replace_after(fixture(), "\"token\": \"n2\"", "40.0", "Infinity"), {"node 'n2'"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"token\": \"n2\"", "40.0", "1e999"), {"node 'n2'"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"token\": \"cp-1\"", "1.5707963267948966", "NaN"),
                                {"carpark_area 'cp-1'", "orientation"});
}

TEST(MapErrors, InvalidArclinePaths) {
  expect_load_error<DataError>(replace_after(fixture(), "\"lane-a\": [", "\"LSL\"", "\"LLL\""),
                               {"arcline_path_3 'lane-a' path #0", "shape", "LLL"});
  expect_load_error<DataError>(replace_after(fixture(), "\"lane-b\": [", "\"RSR\"", "\"rsr\""),
                               {"arcline_path_3 'lane-b' path #1", "shape"});
  expect_load_error<DataError>(replace_after(fixture(), "\"conn-1\": [", "\"radius\": 2.0", "\"radius\": 0.0"),
                               {"arcline_path_3 'conn-1'", "radius"});
  expect_load_error<DataError>(replace_after(fixture(), "\"lane-a\": [", "30.0", "-30.0"),
                               {"arcline_path_3 'lane-a'", "segment_length", "-30.0"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"lane-a\": [", "30.0,", "30.0, 1.0,"),
                                {"arcline_path_3 'lane-a'", "segment_length", "3 finite numbers"});
  expect_load_error<ParseError>(replace_after(fixture(), "\"lane-a\": [", "\"start_pose\"", "\"start\""),
                                {"arcline_path_3 'lane-a'", "start_pose", "missing"});
}

TEST(MapErrors, DuplicateTokens) {
  expect_load_error<DataError>(replace_once(fixture(), "\"token\": \"n2\"", "\"token\": \"n1\""),
                               {"node 'n1'", "unique"});
  expect_load_error<DataError>(replace_once(fixture(), "\"conn-1\": [", "\"lane-a\": ["),
                               {"arcline_path_3 'lane-a'", "once"});
}

}  // namespace
}  // namespace nsg::nuscenes
