#pragma once

// Shared by the gl tests: a fixed gravity map built in code, a fixed scene over it, and a
// screenshot comparison against tests/visual/golden/ with a tolerance.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "autograv/gl/frame_data.h"
#include "autograv/gl/image.h"
#include "autograv/image/image_comparison.h"
#include "autograv/map/gravity_map.h"
#include "explored_fixture_map.h"

namespace autograv::gl::testing {

/// A 5x5x5 map over a 0.16 m cube whose apparent gravity (the force that holds the end-effector)
/// points up and grows toward +x and -z, with a small sideways part: enough variety that a wrong
/// colour ramp or arrow direction shows in the picture.
inline std::shared_ptr<const GravityMap> makeTestMap() {
  WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, 0.02), 0.16, 5);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const Eigen::Vector3d p = grid.vertexPosition(i) - grid.center_m();
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.gravity_n = Eigen::Vector3d(0.8 * p.y(), -0.6 * p.x(), 1.4 + 5.0 * p.x() - 3.0 * p.z());
    v.outcome = VertexOutcome::kConverged;
    v.iterations = 6;
  }
  MapMetadata metadata;
  metadata.device_model = "sim:omni";
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

/// A map made on an explored workspace (an ellipsoid of semi-axes 70, 55, 40 mm about the
/// centre of makeTestMap's cube) with the same field: vertices measured at the vertex, inside the
/// stops and solved (tests/support/explored_fixture_map.h).
inline std::shared_ptr<const GravityMap> makeExploredTestMap() {
  const Eigen::Vector3d center_m(0.0, 0.0, 0.02);
  const auto field = [center_m](const Eigen::Vector3d& x) {
    const Eigen::Vector3d p = x - center_m;
    return Eigen::Vector3d(0.8 * p.y(), -0.6 * p.x(), 1.4 + 5.0 * p.x() - 3.0 * p.z());
  };
  const auto reachable = [center_m](const Eigen::Vector3d& x) {
    return (x - center_m).cwiseQuotient(Eigen::Vector3d(0.070, 0.055, 0.040)).squaredNorm() <= 1.0;
  };
  autograv::testing::ExploredFixtureSpec spec;
  spec.center_m = center_m;
  spec.model = "sim:omni";
  return std::make_shared<const GravityMap>(
      autograv::testing::makeExploredFixtureMap(field, reachable, spec));
}

/// The fixed scene of the screenshot tests: the map, a held cursor with its trail and hand
/// target, the force being sent, a readout and a status line.
inline Scene makeTestScene() {
  Scene scene;
  scene.map = makeTestMap();
  scene.camera = OrbitCamera::framing(scene.map->grid());
  scene.show_cursor = true;
  scene.cursor_m = Eigen::Vector3d(0.01, 0.03, 0.05);
  scene.cursor_held = true;
  for (int i = 0; i <= 40; ++i) {
    const double t = i / 40.0;
    scene.trail_m.emplace_back(0.01 - 0.05 * (1 - t), 0.03 - 0.06 * (1 - t) * (1 - t),
                               0.05 - 0.04 * std::sin(3.0 * (1 - t)));
  }
  scene.show_hand_target = true;
  scene.hand_target_m = Eigen::Vector3d(0.012, 0.036, 0.058);
  scene.show_force = true;
  scene.force_n = scene.map->gravityAt(scene.cursor_m);
  scene.readout = {"SIM:OMNI  COMPENSATION ON 100%", "SERVO 1000.0 HZ  WORST BURST 0.0 MS",
                   "FORCE SENT 0.03 -0.01 1.39 N", "CLAMPS 0  FAULTS 0",
                   "DRIFT SINCE RELEASE 0.0 MM"};
  scene.status_line = "DRAG: MOVE  C: COMPENSATION  A: CALIBRATE";
  return scene;
}

inline std::string goldenPath(const std::string& name) {
  return std::string(AUTOGRAV_SOURCE_DIR) + "/tests/visual/golden/" + name;
}

/// Where a test leaves the pictures it made, to look at after a failure.
inline std::string outputPath(const std::string& name) {
  const std::string folder = std::string(AUTOGRAV_BINARY_DIR) + "/tests/gl_output";
  ::mkdir((std::string(AUTOGRAV_BINARY_DIR) + "/tests").c_str(), 0755);
  ::mkdir(folder.c_str(), 0755);
  return folder + "/" + name;
}

/// A pixel differs when a channel is off by more than this (llvmpipe on another CPU may round
/// edges differently; a wrong colour or a missing object is far beyond it).
inline constexpr int kPixelThreshold = 40;
/// A screenshot matches when at most this fraction of its pixels differ.
inline constexpr double kMaxFractionDiffering = 0.002;

/// The comparison of the gl tests: a pixel differs when a channel is off by more than
/// `threshold`, no shifted edge forgiven; passes at kMaxFractionDiffering. With `diff`, the
/// difference picture too.
inline ImageComparison comparePixels(const RgbImage& actual, const RgbImage& expected,
                                     int threshold, RgbImage* diff = nullptr) {
  ImageComparisonOptions options;
  options.channel_threshold = threshold;
  options.search_radius_px = 0;
  options.tolerance = kMaxFractionDiffering;
  return compareImages(actual, expected, options, diff);
}

/// Compares `actual` with the golden `name`; with AUTOGRAV_UPDATE_GOLDEN=1 in the environment it
/// rewrites the golden instead. The picture and a difference map are left in outputPath().
inline ImageComparison compareWithGolden(const RgbImage& actual, const std::string& name) {
  writePng(actual, outputPath(name));
  const char* update = std::getenv("AUTOGRAV_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    writePng(actual, goldenPath(name));
    ADD_FAILURE() << "golden " << goldenPath(name) << " rewritten; rerun without "
                  << "AUTOGRAV_UPDATE_GOLDEN and look at it before committing";
    return {};
  }
  const RgbImage golden = readPng(goldenPath(name));
  RgbImage diff;
  const ImageComparison difference = comparePixels(actual, golden, kPixelThreshold, &diff);
  if (difference.differing_fraction > kMaxFractionDiffering) {
    writePng(diff, outputPath("diff_" + name));
  }
  return difference;
}

}  // namespace autograv::gl::testing
