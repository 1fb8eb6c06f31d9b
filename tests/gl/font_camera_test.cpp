// Pieces under the renderer: the bitmap font, the encoding of screenshots, the camera.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include "autograv/gl/camera.h"
#include "autograv/gl/image.h"
#include "gl/font.h"
#include "gl/meshes.h"
#include "gl_test_support.h"

namespace autograv::gl {
namespace {

TEST(FontTest, EveryGlyphIsDistinctAndLowerCaseMapsToUpper) {
  std::set<std::string> bitmaps;
  for (int g = 0; g < detail::glyphCount(); ++g) {
    std::string bits;
    for (int y = 0; y < detail::kGlyphHeight; ++y) {
      for (int x = 0; x < detail::kGlyphWidth; ++x) bits += detail::glyphPixel(g, x, y) ? '#' : '.';
    }
    EXPECT_TRUE(bitmaps.insert(bits).second) << "glyph " << g << " repeats another";
  }
  EXPECT_EQ(detail::glyphIndex('a'), detail::glyphIndex('A'));
  EXPECT_EQ(detail::glyphIndex('~'), detail::glyphIndex('?'));
  EXPECT_NE(detail::glyphIndex('0'), detail::glyphIndex('O'));
  EXPECT_FALSE(detail::glyphPixel(detail::glyphIndex(' '), 2, 3));
  EXPECT_TRUE(detail::glyphPixel(detail::glyphIndex('|'), 2, 3));
}

TEST(FontTest, AtlasHoldsEveryGlyphInItsCell) {
  const detail::FontAtlas atlas = detail::buildFontAtlas();
  EXPECT_EQ(atlas.width, detail::kAtlasColumns * detail::kCellWidth);
  const int index = detail::glyphIndex('E');
  const int cx = (index % detail::kAtlasColumns) * detail::kCellWidth;
  const int cy = (index / detail::kAtlasColumns) * detail::kCellHeight;
  for (int x = 0; x < 5; ++x) {  // E: full top row, empty spacing column
    EXPECT_EQ(atlas.texels[static_cast<std::size_t>(cy) * atlas.width + cx + x], 255);
  }
  EXPECT_EQ(atlas.texels[static_cast<std::size_t>(cy) * atlas.width + cx + 5], 0);
}

// The picture type, the codec and the comparison are autograv::image's (tests/image); what is the
// renderer's own is the encoding of its screenshots.
TEST(ScreenshotTest, ScreenshotsAreWrittenSrgbTagged) {
  RgbImage image;
  image.width_px = 7;
  image.height_px = 5;
  image.rgb.assign(7 * 5 * 3, 0);
  image.pixel(6, 4)[0] = 200;
  const std::string path = testing::outputPath("screenshot_bytes.png");
  writePng(image, path);
  std::ifstream file(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes, encodePng(image, PngEncoding::kSrgbTagged));
  EXPECT_EQ(readPng(path).rgb, image.rgb);
  std::remove(path.c_str());
}

TEST(CameraTest, TargetProjectsToTheCentreAndAzimuthZeroLooksAlongMinusX) {
  OrbitCamera camera;
  camera.target_m = Eigen::Vector3d(0.01, 0.02, 0.03);
  camera.distance_m = 0.4;
  camera.azimuth_rad = 0.0;
  camera.elevation_rad = 0.0;
  EXPECT_TRUE(camera.eye_m().isApprox(Eigen::Vector3d(0.41, 0.02, 0.03)));
  const Eigen::Matrix4d vp = camera.projection(4.0 / 3.0) * camera.view();
  const Eigen::Vector4d centre = vp * Eigen::Vector4d(0.01, 0.02, 0.03, 1.0);
  EXPECT_NEAR(centre.x() / centre.w(), 0.0, 1e-12);
  EXPECT_NEAR(centre.y() / centre.w(), 0.0, 1e-12);
  // The operator's view: +y to the right of the screen, +z up.
  const Eigen::Vector4d right = vp * Eigen::Vector4d(0.01, 0.05, 0.03, 1.0);
  const Eigen::Vector4d up = vp * Eigen::Vector4d(0.01, 0.02, 0.06, 1.0);
  EXPECT_GT(right.x() / right.w(), 0.0);
  EXPECT_GT(up.y() / up.w(), 0.0);
}

TEST(CameraTest, DragMovesInTheScreenPlaneByTheRightAmount) {
  OrbitCamera camera;
  camera.distance_m = 0.5;
  camera.azimuth_rad = 0.0;
  camera.elevation_rad = 0.0;
  camera.fov_y_rad = 0.7;
  const int height = 600;
  const Eigen::Vector3d delta = camera.dragDelta_m(100.0, -50.0, camera.target_m, height);
  const double metres_per_px = 2.0 * 0.5 * std::tan(0.35) / height;
  EXPECT_NEAR(delta.x(), 0.0, 1e-12);                    // nothing toward or away from the viewer
  EXPECT_NEAR(delta.y(), 100.0 * metres_per_px, 1e-12);  // mouse right: +y
  EXPECT_NEAR(delta.z(), 50.0 * metres_per_px, 1e-12);   // mouse up: +z
}

TEST(CameraTest, FramingFitsTheGridAndOrbitKeepsElevationBounded) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, 0.01), 0.1, 5);
  OrbitCamera camera = OrbitCamera::framing(grid);
  EXPECT_TRUE(camera.target_m.isApprox(grid.center_m()));
  EXPECT_GT(camera.distance_m, 0.5 * std::sqrt(3.0) * 0.1 / std::sin(0.5 * camera.fov_y_rad));
  camera.orbit(0.0, 1e6);
  EXPECT_LE(camera.elevation_rad, 85.0 * M_PI / 180.0 + 1e-12);
  const double before = camera.distance_m;
  camera.zoom(2.0);
  EXPECT_NEAR(camera.distance_m, before * 0.81, 1e-12);
}

TEST(MeshTest, ArrowAndSphereAreClosedAndUnitNormal) {
  for (const detail::MeshData& mesh : {detail::makeArrowMesh(12), detail::makeSphereMesh(16, 8)}) {
    ASSERT_FALSE(mesh.indices.empty());
    EXPECT_EQ(mesh.indices.size() % 3, 0u);
    for (const std::uint32_t index : mesh.indices) ASSERT_LT(index, mesh.vertices.size());
    for (const detail::MeshVertex& v : mesh.vertices) {
      EXPECT_NEAR(std::hypot(v.normal[0], v.normal[1], v.normal[2]), 1.0, 1e-5);
    }
  }
  // 12 segments: shaft side 2, bottom cap 1, head underside 1, cone 1 triangle each.
  EXPECT_EQ(detail::makeArrowMesh(12).indices.size(), 12u * 5u * 3u);
}

}  // namespace
}  // namespace autograv::gl
