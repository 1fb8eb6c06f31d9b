// autograv-demo's headless pipeline end to end, in-process: a map file, a scripted hand, the
// servo loop on simulated time, OSMesa frames; the last frame matches its golden picture.
#include "demo_app.h"

#include <gtest/gtest.h>

#include <fstream>

#include "autograv/map/map_io.h"
#include "autograv/sim/simulated_device.h"
#include "gl_test_support.h"

namespace autograv::demo {
namespace {

constexpr const char* kDevice = "sim:omni";

/// The device's own ground truth on its default grid, saved as a map file: what a perfect
/// calibration would give, so the picture does not depend on the estimator's tuning.
std::string writeGroundTruthMap() {
  SessionOptions options;
  options.device = kDevice;
  DemoSession session(options);
  const WorkspaceGrid grid = session.calibrationGrid();
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.gravity_n = session.simulation().trueGravity(grid.vertexPosition(i));
    v.outcome = VertexOutcome::kConverged;
    v.iterations = 1;
  }
  MapMetadata metadata;
  metadata.device_model = kDevice;
  metadata.created_utc = "2026-01-01T00:00:00Z";
  const std::string path = gl::testing::outputPath("demo_truth_map.json");
  saveMap(GravityMap(grid, std::move(vertices), metadata), path);
  return path;
}

std::string writeScript() {
  const std::string path = gl::testing::outputPath("demo_hand.txt");
  std::ofstream(path) << "# lift 2 cm up and 1.5 cm to the right, then let go\n"
                         "at 0.10 grab\n"
                         "at 0.15 move 0.0 0.015 0.02 0.1\n"
                         "at 1.00 release\n";
  return path;
}

/// The golden shows sim:omni; a tree without that preset cannot run these tests.
bool omniAvailable() {
  for (const std::string& name : sim::simulatedDeviceNames()) {
    if (name == kDevice) return true;
  }
  return false;
}

DemoOptions headlessOptions() {
  DemoOptions options;
  options.device = kDevice;
  options.map_path = writeGroundTruthMap();
  options.script_path = writeScript();
  options.headless = true;
  options.seconds = 2.0;
  options.frames = 40;
  options.width = 640;
  options.height = 480;
  options.realtime_check = false;
  return options;
}

TEST(DemoHeadlessTest, TwoSecondsWithAMapMatchGoldenAndFloat) {
  if (!omniAvailable()) GTEST_SKIP() << "this tree has no sim:omni preset";
  const HeadlessResult result = runHeadlessFrames(headlessOptions());
  EXPECT_EQ(result.frames, 40);
  EXPECT_EQ(result.ticks_per_frame, 50);
  const ServoSnapshot& s = result.last_snapshot;
  EXPECT_EQ(s.ticks, 2000);
  ASSERT_TRUE(s.released);
  EXPECT_LT(s.drift_m, 0.001) << s.drift_m * 1e3 << " mm";
  EXPECT_EQ(s.faults, 0u);
  EXPECT_DOUBLE_EQ(s.compensation_level, 1.0);
  const ImageComparison difference =
      gl::testing::compareWithGolden(result.last_frame, "gl_demo_headless.png");
  EXPECT_LE(difference.differing_fraction, gl::testing::kMaxFractionDiffering)
      << difference.differing_pixels << " pixels differ; see tests/gl_output/ in the build folder";
}

TEST(DemoHeadlessTest, SameOptionsGiveTheSamePicture) {
  if (!omniAvailable()) GTEST_SKIP() << "this tree has no sim:omni preset";
  const DemoOptions options = headlessOptions();
  const RgbImage first = runHeadlessFrames(options).last_frame;
  const RgbImage second = runHeadlessFrames(options).last_frame;
  EXPECT_EQ(gl::testing::comparePixels(first, second, 0).differing_pixels, 0);
}

TEST(DemoHeadlessTest, WithoutCompensationItFallsAndThePictureShowsIt) {
  if (!omniAvailable()) GTEST_SKIP() << "this tree has no sim:omni preset";
  DemoOptions options = headlessOptions();
  options.session.compensation.enabled = false;
  const HeadlessResult result = runHeadlessFrames(options);
  EXPECT_GT(result.last_snapshot.drift_m, 0.02);
  const RgbImage golden = readPng(gl::testing::goldenPath("gl_demo_headless.png"));
  const ImageComparison difference =
      gl::testing::comparePixels(result.last_frame, golden, gl::testing::kPixelThreshold);
  EXPECT_GT(difference.differing_fraction, gl::testing::kMaxFractionDiffering);
}

}  // namespace
}  // namespace autograv::demo
