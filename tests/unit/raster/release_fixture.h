#pragma once
// The tiny synthetic release (shared by the test processes of the build, read-only), with its
// synth world (the truth), the loaded database and the location's layers at 1 thread.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>

#include "nsg/nuscenes/database.h"
#include "nsg/raster/accumulate.h"
#include "nsg/raster/color_layer.h"
#include "nsg/synth/config.h"
#include "nsg/synth/world.h"
#include "test_support.h"

namespace nsg::raster {

using nuscenes::Database;

class RasterRelease : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    release_ = test::tiny_release();
    const auto config_path = test::source_dir() / "samples/synth/tiny.json";
    config_ = new synth::SynthConfig(synth::SynthConfig::from_file(config_path));
    world_ = new synth::World(synth::build_world(*config_, config_->seed));
    db_ = new Database(Database::load(release_, config_->version));
    const auto t0 = std::chrono::steady_clock::now();
    layers_ = new LocationLayers(accumulate_location(*db_, config_->location, RasterOptions{}, 1));
    seconds_1_thread_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  // A failed release generation fails every test instead of crashing on a null layer.
  void SetUp() override { ASSERT_NE(layers_, nullptr) << "the synthetic release could not be rasterized"; }
  static void TearDownTestSuite() {
    delete colors_;
    colors_ = nullptr;
    delete layers_;
    delete db_;
    delete world_;
    delete config_;
  }

  static inline std::filesystem::path release_;
  static inline synth::SynthConfig* config_ = nullptr;
  static inline synth::World* world_ = nullptr;
  static inline Database* db_ = nullptr;
  static inline LocationLayers* layers_ = nullptr;
  static inline double seconds_1_thread_ = 0.0;
  // The camera layer with default options at 1 thread, computed on first use.
  static const ColorLayer& colors() {
    if (colors_ == nullptr) {
      const auto t0 = std::chrono::steady_clock::now();
      colors_ = new ColorLayer(colorize_location(*db_, config_->location, layers_->lidar, {}, CameraOptions{}, 1));
      color_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return *colors_;
  }
  static inline ColorLayer* colors_ = nullptr;
  static inline double color_seconds_ = 0.0;
};

}  // namespace nsg::raster
