#include "autograv/viz/scene.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/viz/image.h"
#include "autograv/viz/image_compare.h"
#include "viz_test_support.h"

namespace autograv::viz {
namespace {

using testing::analyticGravity;
using testing::countPixels;
using testing::FixtureSpec;
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
