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

  Image draw(const Scene& scene) {
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
  const Image image = draw(makeTestScene());
  ASSERT_EQ(image.width, kWidth);
  ASSERT_EQ(image.height, kHeight);
  const ImageDifference difference = compareWithGolden(image, "gl_scene.png");
  EXPECT_LE(difference.fraction_differing, kMaxFractionDiffering)
      << difference.pixels_differing << " pixels differ; see tests/gl_output/ in the build folder";
}

TEST_F(RendererTest, SameSceneTwiceGivesTheSamePicture) {
  const Image first = draw(makeTestScene());
  const Image second = draw(makeTestScene());
  EXPECT_EQ(compareImages(first, second, 0).pixels_differing, 0);
}

TEST_F(RendererTest, MissingArrowsAreCaughtByTheComparison) {
  Scene scene = makeTestScene();
  scene.show_arrows = false;
  const Image broken = draw(scene);
  const Image whole = draw(makeTestScene());
  const ImageDifference difference = compareImages(broken, whole, kPixelThreshold);
  // 125 arrows cover a few percent of the picture: far beyond the tolerance.
  EXPECT_GT(difference.fraction_differing, 4 * kMaxFractionDiffering);
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
  const ImageDifference difference = compareWithGolden(draw(exploredScene()), "gl_workspace.png");
  EXPECT_LE(difference.fraction_differing, kMaxFractionDiffering)
      << difference.pixels_differing << " pixels differ; see tests/gl_output/ in the build folder";
}

TEST_F(RendererTest, DrawsTheWorkspaceAndTheOffVertexPointsOnlyWhenAsked) {
  const Image whole = draw(exploredScene());
  Scene scene = exploredScene();
  scene.show_workspace = false;
  const Image no_workspace = draw(scene);
  scene = exploredScene();
  scene.show_measurements = false;
  const Image no_measurements = draw(scene);
  EXPECT_GT(compareImages(no_workspace, whole, kPixelThreshold).fraction_differing,
            kMaxFractionDiffering);
  EXPECT_GT(compareImages(no_measurements, whole, kPixelThreshold).fraction_differing,
            kMaxFractionDiffering);
  // Pink beads of the off-vertex points (1.0, 0.55, 0.80), shaded: only with the measurements.
  const auto pink = [](const Image& image) {
    int count = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const int r = image.at(x, y, 0);
        const int g = image.at(x, y, 1);
        const int b = image.at(x, y, 2);
        if (r > 150 && b > 100 && r > g + 50 && b > g + 15) ++count;
      }
    }
    return count;
  };
  EXPECT_GT(pink(whole), pink(no_measurements) + 30);
  // A map without a workspace draws the same with or without the flags.
  Scene plain = makeTestScene();
  const Image plain_shown = draw(plain);
  plain.show_workspace = false;
  plain.show_measurements = false;
  EXPECT_EQ(compareImages(draw(plain), plain_shown, 0).pixels_differing, 0);
}

TEST_F(RendererTest, MissingCursorIsCaughtByTheComparison) {
  Scene scene = makeTestScene();
  scene.show_cursor = false;
  const ImageDifference difference =
      compareImages(draw(scene), draw(makeTestScene()), kPixelThreshold);
  EXPECT_GT(difference.fraction_differing, kMaxFractionDiffering);
}

TEST_F(RendererTest, ArrowsAreColouredFromBlueToRedByMagnitude) {
  // Only the map, seen from the side: the weakest vertices (high z, low x) must come out bluish
  // and the strongest (low z, high x) reddish.
  Scene scene;
  scene.map = testing::makeTestMap();
  scene.camera = OrbitCamera::framing(scene.map->grid());
  scene.show_grid = false;
  scene.show_legend = false;
  const Image image = draw(scene);
  long long reddish = 0;
  long long bluish = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const int r = image.at(x, y, 0);
      const int g = image.at(x, y, 1);
      const int b = image.at(x, y, 2);
      if (r > 120 && r > g + 40 && r > b + 60) ++reddish;
      if (b > 120 && b > r + 60) ++bluish;
    }
  }
  EXPECT_GT(reddish, 200);
  EXPECT_GT(bluish, 200);
}

TEST_F(RendererTest, EmptySceneIsBackgroundOnly) {
  const Image image = draw(Scene{});
  const int r = image.at(0, 0, 0);
  for (int y = 0; y < image.height; y += 37) {
    for (int x = 0; x < image.width; x += 41) ASSERT_EQ(image.at(x, y, 0), r);
  }
  EXPECT_LT(r, 40);
}

TEST_F(RendererTest, ReadoutTextLightsPixelsInTheTopLeftPanel) {
  Scene scene;
  scene.readout = {"SERVO 1000.0 HZ"};
  const Image with_text = draw(scene);
  scene.readout = {"               "};
  const Image blank_text = draw(scene);
  const ImageDifference difference = compareImages(with_text, blank_text, kPixelThreshold);
  EXPECT_GT(difference.pixels_differing, 100);
  // Everything that changed lies in the panel: the top 40 rows.
  long long below = 0;
  for (int y = 40; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (with_text.at(x, y, 0) != blank_text.at(x, y, 0)) ++below;
    }
  }
  EXPECT_EQ(below, 0);
}

}  // namespace
}  // namespace autograv::gl
