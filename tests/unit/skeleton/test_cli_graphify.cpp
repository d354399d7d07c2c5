// `nsgraph graphify` end to end: a folder of masks → a submission that `nsgraph score`
// reads; bad input exits 2 naming the file and writes nothing.
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "graph_masks.h"
#include "nsg/io/raster.h"
#include "test_support.h"

namespace {

using nsg::test::run_nsgraph;

void write_png(const std::filesystem::path& p, const cv::Mat& m) { ASSERT_TRUE(cv::imwrite(p.string(), m)); }

TEST(GraphifyCli, AFolderOfMasksBecomesAScoredSubmission) {
  nsg::test::TempDir dir("graphify_cli");
  std::filesystem::create_directories(dir / "maps");
  nlohmann::json truth = {{"schema_version", "1"}, {"tiles", nlohmann::json::object()}};
  for (const nsg::test::GraphCase& c : nsg::test::graph_cases()) {
    write_png(dir / ("maps/" + c.name + ".png"), nsg::test::draw_mask(c.truth, 7));
    nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
    for (const auto& n : c.truth.nodes) nodes.push_back({n.u, n.v});
    for (const auto& e : c.truth.edges) edges.push_back({e[0], e[1]});
    truth["tiles"][c.name] = {{"nodes", nodes}, {"edges", edges}};
  }
  nsg::test::write_text(dir / "truth.json", truth.dump());
  const auto r = run_nsgraph({"graphify", "--input", (dir / "maps").string(), "--out", (dir / "sub.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = nlohmann::json::parse(nsg::test::read_text(dir / "sub.json"));
  EXPECT_EQ(doc["tiles"].size(), 5u);
  const auto s = run_nsgraph(
      {"score", "--ground-truth", (dir / "truth.json").string(), "--submission", (dir / "sub.json").string()});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_GE(nlohmann::json::parse(s.out)["aggregate"]["mean"]["apls"].get<double>(), 0.95) << s.out;
}

// Directed mode: a folder of headings named as the dataset's vehicle layer
// (<key>.vehicle.tif, float32 GeoTIFF) orients the graphs; the directed APLS of the
// submission is ≥ 0.95. A map without its heading exits 2 naming the key; nothing written.
TEST(GraphifyCli, HeadingFolderGivesDirectedGraphs) {
  nsg::test::TempDir dir("graphify_cli_heading");
  std::filesystem::create_directories(dir / "maps");
  std::filesystem::create_directories(dir / "headings");
  nlohmann::json truth = {{"schema_version", "1"}, {"tiles", nlohmann::json::object()}};
  for (const nsg::test::GraphCase& c : nsg::test::graph_cases()) {
    write_png(dir / ("maps/" + c.name + ".png"), nsg::test::draw_mask(c.truth, 7));
    const cv::Mat h = nsg::test::draw_heading(c.truth, 7);
    nsg::io::Raster r;
    r.width = h.cols;
    r.height = h.rows;
    r.type = nsg::io::SampleType::kFloat32;
    r.data.resize(r.expected_bytes());
    std::memcpy(r.data.data(), h.data, r.data.size());
    nsg::io::GeoRef geo;
    geo.location = "boston-seaport";
    const std::vector<uint8_t> tif = nsg::io::encode_geotiff(r, geo);
    std::ofstream(dir / ("headings/" + c.name + ".vehicle.tif"), std::ios::binary)
        .write(reinterpret_cast<const char*>(tif.data()), static_cast<std::streamsize>(tif.size()));
    nlohmann::json nodes = nlohmann::json::array(), edges = nlohmann::json::array();
    for (const auto& n : c.truth.nodes) nodes.push_back({n.u, n.v});
    for (const auto& e : c.truth.edges) edges.push_back({e[0], e[1]});
    truth["tiles"][c.name] = {{"nodes", nodes}, {"edges", edges}};
  }
  nsg::test::write_text(dir / "truth.json", truth.dump());
  const auto r = run_nsgraph({"graphify", "--input", (dir / "maps").string(), "--heading", (dir / "headings").string(),
                              "--out", (dir / "sub.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = run_nsgraph(
      {"score", "--ground-truth", (dir / "truth.json").string(), "--submission", (dir / "sub.json").string()});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto mean = nlohmann::json::parse(s.out)["aggregate"]["mean"];
  EXPECT_GE(mean["apls_directed"].get<double>(), 0.95) << s.out;
  EXPECT_GE(mean["direction_accuracy"].get<double>(), 0.99) << s.out;

  std::filesystem::remove(dir / "headings/curve.vehicle.tif");
  const auto missing = run_nsgraph({"graphify", "--input", (dir / "maps").string(), "--heading",
                                    (dir / "headings").string(), "--out", (dir / "sub2.json").string()});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("headings: curve: a heading map curve.tif"), std::string::npos) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "sub2.json"));
}

TEST(GraphifyCli, SetAndListOptionsUseTheDeclaredKeys) {
  const auto list = run_nsgraph({"graphify", "--list-options"});
  ASSERT_EQ(list.exit_code, 0) << list.err;
  for (const char* key :
       {"threshold", "smooth_sigma_px", "min_component_px", "min_spur_px", "simplify_tolerance_px", "anchor_spacing_px",
        "split_crossings", "crossing_tolerance_deg", "crossing_merge_px", "heading_window_px"})
    EXPECT_NE(list.out.find(key), std::string::npos) << key;
  const auto bad = run_nsgraph({"graphify", "--input", "x.png", "--out", "y.json", "--set", "treshold=0.4"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("threshold"), std::string::npos) << bad.err;
}

TEST(GraphifyCli, BadInputExitsTwoNamingTheFileAndWritesNothing) {
  nsg::test::TempDir dir("graphify_cli_bad");
  std::vector<uint8_t> png;
  cv::imencode(".png", cv::Mat(64, 64, CV_8U, cv::Scalar(255)), png);
  std::ofstream(dir / "cut.png", std::ios::binary).write(reinterpret_cast<const char*>(png.data()), 40);
  for (const std::string name : {"cut.png", "missing.npy"}) {
    const auto r = run_nsgraph({"graphify", "--input", (dir / name).string(), "--out", (dir / "out.json").string()});
    EXPECT_EQ(r.exit_code, 2) << name;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.json"));
  }
}

}  // namespace
