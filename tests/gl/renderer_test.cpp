// The renderer draws a fixed scene through OSMesa (no display) that matches its golden picture,
// and the comparison catches a render with a part missing.
#include "autograv/gl/renderer.h"

#include <gtest/gtest.h>

#include "autograv/gl/offscreen_context.h"
#include "gl_test_support.h"

namespace autograv::gl {
namespace {

using testing::compareWithGolden;
using testing::kMaxFractionDiffering;
using testing::kPixelThreshold;
using testing::makeTestScene;

constexpr int kWidth = 640;
constexpr int kHeight = 480;

class RendererTest : public ::testing::Test {
 protected:
  RendererTest() : context_(kWidth, kHeight), renderer_(context_) {}

  RgbImage draw(const Scene& scene) {
    renderer_.render(scene);
    return context_.readImage();
  }

  OffscreenContext context_;
  Renderer renderer_;
};

TEST_F(RendererTest, ReportsACoreContextOfAtLeast33) {
  EXPECT_NE(renderer_.glVersion().find("Core"), std::string::npos) << renderer_.glVersion();
  EXPECT_EQ(renderer_.shaderOrigin(), "embedded");
}

TEST_F(RendererTest, FixedSceneMatchesGolden) {
  const RgbImage image = draw(makeTestScene());
  ASSERT_EQ(image.width_px, kWidth);
  ASSERT_EQ(image.height_px, kHeight);
  const ImageComparison difference = compareWithGolden(image, "gl_scene.png");
  EXPECT_LE(difference.differing_fraction, kMaxFractionDiffering)
      << difference.differing_pixels << " pixels differ; see tests/gl_output/ in the build folder";
}

TEST_F(RendererTest, SameSceneTwiceGivesTheSamePicture) {
  const RgbImage first = draw(makeTestScene());
  const RgbImage second = draw(makeTestScene());
  EXPECT_EQ(testing::comparePixels(first, second, 0).differing_pixels, 0);
}

TEST_F(RendererTest, MissingArrowsAreCaughtByTheComparison) {
  Scene scene = makeTestScene();
  scene.show_arrows = false;
  const RgbImage broken = draw(scene);
  const RgbImage whole = draw(makeTestScene());
  const ImageComparison difference = testing::comparePixels(broken, whole, kPixelThreshold);
  // 125 arrows cover a few percent of the picture: far beyond the tolerance.
  EXPECT_GT(difference.differing_fraction, 4 * kMaxFractionDiffering);
}

// The explored workspace's wire hull and stops, and the points measured inside the stops.
Scene exploredScene() {
  Scene scene = makeTestScene();
  scene.map = testing::makeExploredTestMap();
  scene.camera = OrbitCamera::framing(scene.map->grid());
  scene.force_n = scene.map->gravityAt(scene.cursor_m);
  return scene;
}

TEST_F(RendererTest, ExploredWorkspaceSceneMatchesGolden) {
  const ImageComparison difference = compareWithGolden(draw(exploredScene()), "gl_workspace.png");
  EXPECT_LE(difference.differing_fraction, kMaxFractionDiffering)
      << difference.differing_pixels << " pixels differ; see tests/gl_output/ in the build folder";
}

TEST_F(RendererTest, DrawsTheWorkspaceAndTheOffVertexPointsOnlyWhenAsked) {
  const RgbImage whole = draw(exploredScene());
  Scene scene = exploredScene();
  scene.show_workspace = false;
  const RgbImage no_workspace = draw(scene);
  scene = exploredScene();
  scene.show_measurements = false;
  const RgbImage no_measurements = draw(scene);
  EXPECT_GT(testing::comparePixels(no_workspace, whole, kPixelThreshold).differing_fraction,
            kMaxFractionDiffering);
  EXPECT_GT(testing::comparePixels(no_measurements, whole, kPixelThreshold).differing_fraction,
            kMaxFractionDiffering);
  // Pink beads of the off-vertex points (1.0, 0.55, 0.80), shaded: only with the measurements.
  const auto pink = [](const RgbImage& image) {
    int count = 0;
    for (int y = 0; y < image.height_px; ++y) {
      for (int x = 0; x < image.width_px; ++x) {
        const int r = image.pixel(x, y)[0];
        const int g = image.pixel(x, y)[1];
        const int b = image.pixel(x, y)[2];
        if (r > 150 && b > 100 && r > g + 50 && b > g + 15) ++count;
      }
    }
    return count;
  };
  EXPECT_GT(pink(whole), pink(no_measurements) + 30);
  // A map without a workspace draws the same with or without the flags.
  Scene plain = makeTestScene();
  const RgbImage plain_shown = draw(plain);
  plain.show_workspace = false;
  plain.show_measurements = false;
  EXPECT_EQ(testing::comparePixels(draw(plain), plain_shown, 0).differing_pixels, 0);
}

TEST_F(RendererTest, MissingCursorIsCaughtByTheComparison) {
  Scene scene = makeTestScene();
  scene.show_cursor = false;
  const ImageComparison difference =
      testing::comparePixels(draw(scene), draw(makeTestScene()), kPixelThreshold);
  EXPECT_GT(difference.differing_fraction, kMaxFractionDiffering);
}

TEST_F(RendererTest, ArrowsAreColouredFromBlueToRedByMagnitude) {
  // Only the map, seen from the side: the weakest vertices (high z, low x) must come out bluish
  // and the strongest (low z, high x) reddish.
  Scene scene;
  scene.map = testing::makeTestMap();
  scene.camera = OrbitCamera::framing(scene.map->grid());
  scene.show_grid = false;
  scene.show_legend = false;
  const RgbImage image = draw(scene);
  long long reddish = 0;
  long long bluish = 0;
  for (int y = 0; y < image.height_px; ++y) {
    for (int x = 0; x < image.width_px; ++x) {
      const int r = image.pixel(x, y)[0];
      const int g = image.pixel(x, y)[1];
      const int b = image.pixel(x, y)[2];
      if (r > 120 && r > g + 40 && r > b + 60) ++reddish;
      if (b > 120 && b > r + 60) ++bluish;
    }
  }
  EXPECT_GT(reddish, 200);
  EXPECT_GT(bluish, 200);
}

TEST_F(RendererTest, EmptySceneIsBackgroundOnly) {
  const RgbImage image = draw(Scene{});
  const int r = image.pixel(0, 0)[0];
  for (int y = 0; y < image.height_px; y += 37) {
    for (int x = 0; x < image.width_px; x += 41) ASSERT_EQ(image.pixel(x, y)[0], r);
  }
  EXPECT_LT(r, 40);
}

TEST_F(RendererTest, ReadoutTextLightsPixelsInTheTopLeftPanel) {
  Scene scene;
  scene.readout = {"SERVO 1000.0 HZ"};
  const RgbImage with_text = draw(scene);
  scene.readout = {"               "};
  const RgbImage blank_text = draw(scene);
  const ImageComparison difference = testing::comparePixels(with_text, blank_text, kPixelThreshold);
  EXPECT_GT(difference.differing_pixels, 100);
  // Everything that changed lies in the panel: the top 40 rows.
  long long below = 0;
  for (int y = 40; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (with_text.pixel(x, y)[0] != blank_text.pixel(x, y)[0]) ++below;
    }
  }
  EXPECT_EQ(below, 0);
}

}  // namespace
}  // namespace autograv::gl
