#include "autograv/viz/scene.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/image/image_comparison.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/viz/image.h"
#include "viz_test_support.h"

namespace autograv::viz {
namespace {

using testing::analyticGravity;
using testing::countPixels;
using testing::FixtureSpec;
using testing::makeExploredFixtureMap;
using testing::makeFixtureMap;

constexpr int kWidth = 400;
constexpr int kHeight = 300;

SceneOptions smallScene() {
  SceneOptions options;
  options.width_px = kWidth;
  options.height_px = kHeight;
  return options;
}

bool isMarkerRed(int r, int g, int b) { return r > 150 && g < 60 && b < 60; }
bool isDeviceOrange(int r, int g, int b) { return r > 200 && g > 90 && g < 170 && b < 50; }

// Restores DISPLAY when a test that removed it ends.
class DisplayRemoved {
 public:
  DisplayRemoved() {
    const char* value = std::getenv("DISPLAY");
    if (value != nullptr) saved_ = value;
    had_ = value != nullptr;
    ::unsetenv("DISPLAY");
  }
  ~DisplayRemoved() {
    if (had_) ::setenv("DISPLAY", saved_.c_str(), 1);
  }

 private:
  std::string saved_;
  bool had_ = false;
};

TEST(SceneSummaryTest, CountsAndRanges) {
  FixtureSpec spec;
  spec.failed = {3, 40};
  spec.not_visited = {124};
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  const SceneSummary summary = summarizeScene(map);
  EXPECT_EQ(summary.vertices, 125);
  EXPECT_EQ(summary.converged, 122);
  EXPECT_EQ(summary.failed, 2);
  EXPECT_EQ(summary.not_visited, 1);
  double lo = 1e9;
  double hi = 0.0;
  for (const auto& v : map.vertices()) {
    if (v.gravity_n.norm() == 0.0) continue;
    lo = std::min(lo, v.gravity_n.norm());
    hi = std::max(hi, v.gravity_n.norm());
  }
  EXPECT_DOUBLE_EQ(summary.min_gravity_n, lo);
  EXPECT_DOUBLE_EQ(summary.max_gravity_n, hi);
  EXPECT_EQ(summary.max_residual_n, 0.0);  // no ground truth given
}

TEST(SceneSummaryTest, ResidualOfAnExactMapIsTheInterpolationError) {
  // Estimates equal to the truth at every vertex: what remains is trilinear interpolation error
  // of the field's 20 x^2 term, at most 20 h^2 / 4 with h = 20 mm (reached mid-cell).
  FixtureSpec spec;
  spec.error_fraction = 0.0;
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  const SceneSummary summary = summarizeScene(map, analyticGravity);
  EXPECT_NEAR(summary.max_residual_n, 20.0 * 0.02 * 0.02 / 4.0, 1e-9);
}

TEST(SceneSummaryTest, UnvisitedVerticesLeaveNoResidual) {
  // A never-visited vertex has a zero estimate: its cells are "no data", not a 2 N residual.
  FixtureSpec spec;
  spec.error_fraction = 0.0;
  spec.not_visited = {0, 62};
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  EXPECT_LE(summarizeScene(map, analyticGravity).max_residual_n, 0.002 + 1e-9);
}

// An ellipsoidal workspace (semi-axes 60, 45, 35 mm about the origin) for the explored maps.
bool insideEllipsoid(const Eigen::Vector3d& x) {
  return (x.cwiseQuotient(Eigen::Vector3d(0.060, 0.045, 0.035))).squaredNorm() <= 1.0;
}

GravityMap exploredMap() { return makeExploredFixtureMap(analyticGravity, insideEllipsoid); }

TEST(SceneSummaryTest, CountsEachKindOfValueAsThePlanMadeIt) {
  const GravityMap map = exploredMap();
  const MeasurementPlan plan = planMeasurements(map.grid(), map.metadata().workspace);
  const SceneSummary summary = summarizeScene(map);
  EXPECT_EQ(summary.vertices, 125);
  EXPECT_EQ(summary.workspace_directions, 26);
  EXPECT_GT(plan.off_vertex, 0);
  EXPECT_GT(plan.skipped, 0);
  EXPECT_EQ(summary.measured_at_vertex, plan.at_vertex);
  EXPECT_EQ(summary.measured_off_vertex, plan.off_vertex);
  EXPECT_EQ(summary.solved, plan.skipped);
  EXPECT_EQ(summary.filled, plan.off_vertex + plan.skipped);
  EXPECT_EQ(summary.failed, 0);
  EXPECT_EQ(summary.not_visited, 0);
  // A map without an exploration: every value measured at its vertex.
  const SceneSummary plain = summarizeScene(makeFixtureMap(analyticGravity));
  EXPECT_EQ(plain.measured_at_vertex, 125);
  EXPECT_EQ(plain.measured_off_vertex + plain.solved + plain.workspace_directions, 0);
}

bool isOffVertexPink(int r, int g, int b) {
  // paletteFor(kWhite).off_vertex = (0.80, 0.40, 0.65), lit and seen through the workspace.
  return r > 150 && g > 60 && g < 140 && b > 110 && b < 200 && r > b + 15 && b > g + 25;
}

TEST(SceneTest, ShowsThePointsMeasuredInsideTheStops) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const int plain =
      countPixels(renderScene(makeFixtureMap(analyticGravity), smallScene()), isOffVertexPink);
  const int explored = countPixels(renderScene(exploredMap(), smallScene()), isOffVertexPink);
  EXPECT_EQ(plain, 0);
  // Beads at every off-vertex point, the lines to their vertices and the legend symbol.
  EXPECT_GT(explored, 60);
}

TEST(SceneTest, DrawsTheExploredWorkspaceInPlaceOfTheSphere) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const GravityMap map = exploredMap();
  SceneOptions options = smallScene();
  options.workspace_radius_m = 0.07;
  const RgbImage with_workspace = renderScene(map, options);
  options.show_explored_workspace = false;
  const RgbImage sphere = renderScene(map, options);
  // The sphere is 70 mm round, the explored workspace an ellipsoid: the pictures differ, and a
  // map without a workspace is drawn the same either way.
  EXPECT_GT(compareImages(with_workspace, sphere).differing_fraction, 0.01);
  const GravityMap plain = makeFixtureMap(analyticGravity);
  options.show_explored_workspace = true;
  const RgbImage plain_shown = renderScene(plain, options);
  options.show_explored_workspace = false;
  EXPECT_EQ(renderScene(plain, options).rgb, plain_shown.rgb);
}

TEST(SceneTest, FailsClearlyWithoutADisplay) {
  const GravityMap map = makeFixtureMap(analyticGravity);
  DisplayRemoved no_display;
  std::string reason;
  EXPECT_FALSE(displayAvailable(&reason));
  EXPECT_NE(reason.find("xvfb-run -a"), std::string::npos) << reason;
  try {
    renderScene(map, smallScene());
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("DISPLAY is not set"), std::string::npos)
        << error.what();
  }
}

TEST(SceneTest, RejectsBadOptionsBeforeRendering) {
  const GravityMap map = makeFixtureMap(analyticGravity);
  SceneOptions options = smallScene();
  options.width_px = 8;
  EXPECT_THROW(renderScene(map, options), Error);
  options = smallScene();
  options.height_px = 10000;
  EXPECT_THROW(renderScene(map, options), Error);
  options = smallScene();
  options.camera_azimuth_deg = NAN;
  EXPECT_THROW(renderScene(map, options), Error);
  options = smallScene();
  options.workspace_radius_m = -0.1;
  EXPECT_THROW(renderScene(map, options), Error);
  options = smallScene();
  options.device_position_m = Eigen::Vector3d(0.0, NAN, 0.0);
  EXPECT_THROW(renderScene(map, options), Error);
}

TEST(SceneTest, RendersTheRequestedSizeOnTheRequestedBackground) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const GravityMap map = makeFixtureMap(analyticGravity);
  SceneOptions options = smallScene();
  const RgbImage white = renderScene(map, options);
  ASSERT_EQ(white.width_px, kWidth);
  ASSERT_EQ(white.height_px, kHeight);
  const std::uint8_t* corner = white.pixel(kWidth - 2, kHeight - 2);
  EXPECT_EQ(corner[0], 255);
  EXPECT_EQ(corner[1], 255);
  EXPECT_EQ(corner[2], 255);
  options.background = Background::kDark;
  const RgbImage dark = renderScene(map, options);
  corner = dark.pixel(kWidth - 2, kHeight - 2);
  // paletteFor(kDark).background = (0.09, 0.10, 0.13)
  EXPECT_NEAR(corner[0], 23, 1);
  EXPECT_NEAR(corner[1], 26, 1);
  EXPECT_NEAR(corner[2], 33, 1);
  // Text and arrows are drawn: a good share of pixels differ from the background.
  const int drawn = countPixels(white, [](int r, int g, int b) { return r + g + b < 600; });
  EXPECT_GT(drawn, kWidth * kHeight / 50);
}

TEST(SceneTest, MarksFailedVerticesInRed) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const RgbImage clean = renderScene(makeFixtureMap(analyticGravity), smallScene());
  FixtureSpec spec;
  spec.failed = {31, 93};
  const RgbImage marked = renderScene(makeFixtureMap(analyticGravity, spec), smallScene());
  const int red_clean = countPixels(clean, isMarkerRed);
  const int red_marked = countPixels(marked, isMarkerRed);
  EXPECT_EQ(red_clean, 0);
  // Two spheres plus the legend symbol and its text.
  EXPECT_GT(red_marked, 40);
}

TEST(SceneTest, DrawsTheDevicePosition) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const GravityMap map = makeFixtureMap(analyticGravity);
  SceneOptions options = smallScene();
  const int before = countPixels(renderScene(map, options), isDeviceOrange);
  options.device_position_m = Eigen::Vector3d(0.01, 0.0, 0.0);
  const int after = countPixels(renderScene(map, options), isDeviceOrange);
  EXPECT_EQ(before, 0);
  EXPECT_GT(after, 30);
}

TEST(SceneTest, CameraPresetsShowDifferentPictures) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const GravityMap map = makeFixtureMap(analyticGravity);
  SceneOptions options = smallScene();
  const RgbImage iso = renderScene(map, options);
  options.view = CameraView::kFront;
  const RgbImage front = renderScene(map, options);
  options.view = CameraView::kTop;
  const RgbImage top = renderScene(map, options);
  EXPECT_GT(compareImages(front, iso).differing_fraction, 0.01);
  EXPECT_GT(compareImages(top, iso).differing_fraction, 0.01);
  EXPECT_GT(compareImages(top, front).differing_fraction, 0.01);
  // The same options give the same picture, bit for bit.
  EXPECT_EQ(renderScene(map, options).rgb, top.rgb);
}

TEST(SceneTest, GroundTruthAddsTheResidualField) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const GravityMap map = makeFixtureMap(analyticGravity);
  SceneOptions options = smallScene();
  const RgbImage plain = renderScene(map, options);
  options.ground_truth = analyticGravity;
  const RgbImage residual = renderScene(map, options);
  // The residual colour map runs from white to dark red: reddish pixels appear.
  const auto reddish = [](int r, int g, int b) { return r > 120 && r > g + 50 && r > b + 50; };
  EXPECT_GT(countPixels(residual, reddish), countPixels(plain, reddish) + 500);
}

TEST(SceneTest, ViewNamesRoundTrip) {
  for (const CameraView view : {CameraView::kIso, CameraView::kFront, CameraView::kTop}) {
    CameraView parsed = CameraView::kIso;
    ASSERT_TRUE(parseCameraView(toString(view), parsed));
    EXPECT_EQ(parsed, view);
  }
  CameraView parsed = CameraView::kFront;
  EXPECT_FALSE(parseCameraView("side", parsed));
  Background background = Background::kWhite;
  EXPECT_TRUE(parseBackground("dark", background));
  EXPECT_EQ(background, Background::kDark);
  EXPECT_FALSE(parseBackground("black", background));
  ColorMap color_map = ColorMap::kViridis;
  EXPECT_TRUE(parseColorMap("coolwarm", color_map));
  EXPECT_EQ(color_map, ColorMap::kCoolWarm);
  EXPECT_FALSE(parseColorMap("jet", color_map));
}

}  // namespace
}  // namespace autograv::viz
