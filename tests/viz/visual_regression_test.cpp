// Screenshot regression: renders fixed fixture maps headless and compares them with the golden
// PNGs in tests/visual/golden/. Deliberately broken renders (a missing arrow, another colour map,
// a moved camera) must fail the same comparison; a render that differs only by rasterizer-level
// rounding must pass.
//
// Regenerate the goldens (after an intended change of the pictures) with
//   tests/visual/regenerate_goldens.sh [build-dir]
// which runs this binary with AUTOGRAV_UPDATE_GOLDENS=1 under xvfb-run.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/image/image_comparison.h"
#include "autograv/map/map_io.h"
#include "autograv/map/value_kind.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/viz/image.h"
#include "autograv/viz/plots.h"
#include "autograv/viz/scene.h"
#include "viz_test_support.h"

namespace autograv::viz {
namespace {

constexpr int kGoldenWidth = 640;
constexpr int kGoldenHeight = 480;
// The fixture maps' devices and seeds (see tests/visual/regenerate_goldens.sh).
constexpr std::uint64_t kSeed = 1;

std::string goldenPath(const std::string& name) {
  return std::string(AUTOGRAV_SOURCE_DIR) + "/tests/visual/golden/" + name;
}

std::string outputPath(const std::string& name) {
  return std::string(AUTOGRAV_BINARY_DIR) + "/visual_regression_" + name;
}

bool envIsOne(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr && std::string(value) == "1";
}

bool updatingGoldens() { return envIsOne("AUTOGRAV_UPDATE_GOLDENS"); }

// A simulated device kept alive for its ground truth and workspace.
struct Device {
  std::shared_ptr<sim::SimulatedDevice> device;
  GroundTruth truth() const {
    auto d = device;
    return [d](const Eigen::Vector3d& x) { return d->trueGravity(x); };
  }
};

Device openDevice(const std::string& name) {
  Device result{sim::makeSimulatedDevice(name, kSeed)};
  result.device->open();
  return result;
}

const GravityMap& omegaMap() {
  static const GravityMap map = loadMap(goldenPath("omega_map.json"));
  return map;
}

// The omni fixture is made here rather than by the calibrator: the omni's true field, a small
// deterministic estimation error, synthetic convergence histories and a few vertices marked as
// failed, so that the pictures show every kind of marker. Written by
// AUTOGRAV_UPDATE_FIXTURES=1 (tests/visual/regenerate_goldens.sh --maps).
void writeOmniFixture() {
  const Device omni = openDevice("sim:omni");
  testing::FixtureSpec spec;
  spec.center_m = omni.device->workspaceCenter_m();
  // The calibrator's default grid: 80 % of the cube inscribed in the workspace sphere.
  spec.side_m = std::round(0.8 * 2.0 * omni.device->specifications().workspace_radius_m /
                           std::sqrt(3.0) * 1e3) *
                1e-3;
  spec.resolution = 4;
  spec.failed = {5, 38};
  spec.not_visited = {63};
  spec.error_fraction = 0.006;
  spec.model = "sim:omni";
  saveMap(testing::makeFixtureMap(omni.truth(), spec), goldenPath("omni_map.json"));
  std::printf("  wrote %s\n", goldenPath("omni_map.json").c_str());
}

// A map of sim:falcon made as a calibration on its explored workspace makes one (every kind of
// value: measured at the vertex, inside the stops, solved), in milliseconds: the probes' stops
// from the simulator's reach, the plan, the solve (tests/support/explored_fixture_map.h).
// Written with the omni fixture. The falcon's workspace is the least round (52-81 mm of reach).
void writeFalconExploredFixture() {
  const Device falcon = openDevice("sim:falcon");
  auto device = falcon.device;
  autograv::testing::ExploredFixtureSpec spec;
  spec.center_m = device->workspaceCenter_m();
  spec.model = "sim:falcon";
  const GravityMap map = autograv::testing::makeExploredFixtureMap(
      falcon.truth(), [device](const Eigen::Vector3d& x) { return device->isReachable(x); }, spec);
  saveMap(map, goldenPath("falcon_explored_map.json"));
  std::printf("  wrote %s\n", goldenPath("falcon_explored_map.json").c_str());
}

const GravityMap& falconExploredMap() {
  static const GravityMap map = loadMap(goldenPath("falcon_explored_map.json"));
  return map;
}

const GravityMap& omniMap() {
  static const GravityMap map = loadMap(goldenPath("omni_map.json"));
  return map;
}

SceneOptions goldenScene(const Device& device) {
  SceneOptions options;
  options.width_px = kGoldenWidth;
  options.height_px = kGoldenHeight;
  options.workspace_radius_m = device.device->specifications().workspace_radius_m;
  options.workspace_center_m = device.device->workspaceCenter_m();
  return options;
}

struct GoldenCase {
  std::string file;
  std::function<RgbImage()> render;
};

std::vector<GoldenCase> goldenCases() {
  return {
      {"omega_iso.png",
       [] {
         const Device omega = openDevice("sim:omega");
         SceneOptions options = goldenScene(omega);
         options.device_position_m = omega.device->workspaceCenter_m();
         return renderScene(omegaMap(), options);
       }},
      {"omni_front_dark.png",
       [] {
         SceneOptions options;
         options.width_px = kGoldenWidth;
         options.height_px = kGoldenHeight;
         options.view = CameraView::kFront;
         options.background = Background::kDark;
         return renderScene(omniMap(), options);
       }},
      {"omega_top_residual.png",
       [] {
         const Device omega = openDevice("sim:omega");
         SceneOptions options = goldenScene(omega);
         options.view = CameraView::kTop;
         options.ground_truth = omega.truth();
         return renderScene(omegaMap(), options);
       }},
      {"falcon_explored_iso.png",
       [] {
         SceneOptions options;
         options.width_px = kGoldenWidth;
         options.height_px = kGoldenHeight;
         return renderScene(falconExploredMap(), options);
       }},
      {"falcon_explored_front_dark_residual.png",
       [] {
         const Device falcon = openDevice("sim:falcon");
         auto device = falcon.device;
         SceneOptions options = goldenScene(falcon);
         options.view = CameraView::kFront;
         options.background = Background::kDark;
         options.ground_truth = falcon.truth();
         options.reachable = [device](const Eigen::Vector3d& x) { return device->isReachable(x); };
         return renderScene(falconExploredMap(), options);
       }},
      {"omega_convergence.png",
       [] {
         const Device omega = openDevice("sim:omega");
         PlotOptions options;
         options.width_px = kGoldenWidth;
         options.height_px = kGoldenHeight;
         options.ground_truth = omega.truth();
         return renderConvergencePlot(omegaMap(), omegaMap().grid().vertexCount() / 2, options);
       }},
      {"omni_summary.png",
       [] {
         const Device omni = openDevice("sim:omni");
         PlotOptions options;
         options.width_px = kGoldenWidth;
         options.height_px = kGoldenHeight;
         options.ground_truth = omni.truth();
         return renderSummaryPlot(omniMap(), options);
       }},
  };
}

// Compares with the golden picture; on failure keeps the render and a difference picture in the
// build folder for the failure message.
ImageComparison compareWithGolden(const RgbImage& image, const std::string& file) {
  const RgbImage golden = readPng(goldenPath(file));
  RgbImage diff;
  const ImageComparisonOptions options;
  const ImageComparison result = compareImages(image, golden, options, &diff);
  std::printf("  %-24s %s\n", file.c_str(), describe(result, options).c_str());
  if (!result.passed) {
    writePng(image, outputPath(file));
    writePng(diff, outputPath("diff_" + file));
  }
  return result;
}

class VisualRegressionTest : public ::testing::Test {
 protected:
  void SetUp() override { AUTOGRAV_REQUIRE_DISPLAY(); }
};

TEST_F(VisualRegressionTest, RendersMatchTheGoldens) {
  if (envIsOne("AUTOGRAV_UPDATE_FIXTURES")) {
    writeOmniFixture();
    writeFalconExploredFixture();
  }
  for (const GoldenCase& golden : goldenCases()) {
    SCOPED_TRACE(golden.file);
    const RgbImage image = golden.render();
    if (updatingGoldens()) {
      writePng(image, goldenPath(golden.file));
      std::printf("  wrote %s\n", goldenPath(golden.file).c_str());
      continue;
    }
    const ImageComparison result = compareWithGolden(image, golden.file);
    EXPECT_TRUE(result.passed) << golden.file << " departs from its golden picture; see "
                               << outputPath(golden.file) << " and "
                               << outputPath("diff_" + golden.file)
                               << ". If the change is intended, run "
                                  "tests/visual/regenerate_goldens.sh";
  }
}

// The broken renders below start from the omega_iso golden case.
RgbImage omegaIso(const std::function<void(SceneOptions&)>& change,
                  const std::function<void(std::vector<VertexEstimate>&)>& edit = nullptr) {
  const Device omega = openDevice("sim:omega");
  SceneOptions options = goldenScene(omega);
  options.device_position_m = omega.device->workspaceCenter_m();
  if (change) change(options);
  if (!edit) return renderScene(omegaMap(), options);
  std::vector<VertexEstimate> vertices = omegaMap().vertices();
  edit(vertices);
  const GravityMap edited(omegaMap().grid(), vertices, omegaMap().metadata());
  return renderScene(edited, options);
}

TEST_F(VisualRegressionTest, RasterizerRoundingPasses) {
  if (updatingGoldens()) GTEST_SKIP() << "updating goldens";
  // A camera turned by a thousandth of a degree and estimates changed in their 9th digit move
  // edges by a fraction of a pixel: what another llvmpipe build's rounding looks like.
  const RgbImage image = omegaIso([](SceneOptions& o) { o.camera_azimuth_deg = 0.001; },
                                  [](std::vector<VertexEstimate>& vertices) {
                                    for (auto& v : vertices) v.gravity_n *= 1.0 + 1e-9;
                                  });
  EXPECT_TRUE(compareWithGolden(image, "omega_iso.png").passed);
}

TEST_F(VisualRegressionTest, MissingArrowFails) {
  if (updatingGoldens()) GTEST_SKIP() << "updating goldens";
  // One vertex without an estimate: its arrow is gone (it stays "converged", so no marker). The
  // vertex is measured where it stands (a value beyond the stops would be solved again from the
  // others), on the top layer measured at a vertex, near the camera: its arrow is in plain view
  // and does not set the bounds that frame the camera.
  const WorkspaceGrid& grid = omegaMap().grid();
  int vertex = -1;
  for (int z = grid.resolution().z() - 1; z >= 0 && vertex < 0; --z) {
    for (int i = 0; i < grid.vertexCount() && vertex < 0; ++i) {
      const bool top = grid.vertexCoordinates(i).z() == z;
      if (top && valueKind(omegaMap().vertices()[static_cast<std::size_t>(i)]) ==
                     ValueKind::kAtVertex) {
        vertex = i;
      }
    }
  }
  ASSERT_GE(vertex, 0);
  const RgbImage image = omegaIso(nullptr, [vertex](std::vector<VertexEstimate>& vertices) {
    vertices[static_cast<std::size_t>(vertex)].gravity_n.setZero();
  });
  EXPECT_FALSE(compareWithGolden(image, "omega_iso.png").passed);
}

TEST_F(VisualRegressionTest, WrongColourMapFails) {
  if (updatingGoldens()) GTEST_SKIP() << "updating goldens";
  const RgbImage image = omegaIso([](SceneOptions& o) { o.color_map = ColorMap::kCoolWarm; });
  EXPECT_FALSE(compareWithGolden(image, "omega_iso.png").passed);
}

TEST_F(VisualRegressionTest, MovedCameraFails) {
  if (updatingGoldens()) GTEST_SKIP() << "updating goldens";
  const RgbImage image = omegaIso([](SceneOptions& o) { o.camera_azimuth_deg = 2.0; });
  EXPECT_FALSE(compareWithGolden(image, "omega_iso.png").passed);
}

// The broken renders below start from the falcon_explored_iso golden case.
RgbImage falconExploredIso(const std::function<void(SceneOptions&)>& change,
                           const std::function<void(std::vector<VertexEstimate>&)>& edit) {
  SceneOptions options;
  options.width_px = kGoldenWidth;
  options.height_px = kGoldenHeight;
  if (change) change(options);
  if (!edit) return renderScene(falconExploredMap(), options);
  std::vector<VertexEstimate> vertices = falconExploredMap().vertices();
  edit(vertices);
  const GravityMap edited(falconExploredMap().grid(), vertices, falconExploredMap().metadata());
  return renderScene(edited, options);
}

TEST_F(VisualRegressionTest, MissingExploredWorkspaceFails) {
  if (updatingGoldens()) GTEST_SKIP() << "updating goldens";
  const RgbImage image =
      falconExploredIso([](SceneOptions& o) { o.show_explored_workspace = false; }, nullptr);
  EXPECT_FALSE(compareWithGolden(image, "falcon_explored_iso.png").passed);
}

TEST_F(VisualRegressionTest, MissingOffVertexPointsFail) {
  if (updatingGoldens()) GTEST_SKIP() << "updating goldens";
  // The same values, but as if every one had been measured at its vertex: no beads, no lines.
  const RgbImage image = falconExploredIso(nullptr, [](std::vector<VertexEstimate>& vertices) {
    for (VertexEstimate& v : vertices) {
      v.measured_at_m.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  });
  EXPECT_FALSE(compareWithGolden(image, "falcon_explored_iso.png").passed);
}

}  // namespace
}  // namespace autograv::viz
