#include "autograv/viz/image_compare.h"

#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/viz/image.h"

// Image comparison and PNG input/output need no X display.
namespace autograv::viz {
namespace {

RgbImage filled(int width, int height, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  RgbImage image;
  image.width_px = width;
  image.height_px = height;
  image.rgb.resize(static_cast<std::size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = image.pixel(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
    }
  }
  return image;
}

void paintRect(RgbImage& image, int x0, int y0, int w, int h, std::uint8_t r, std::uint8_t g,
               std::uint8_t b) {
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      std::uint8_t* p = image.pixel(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
    }
  }
}

std::string scratchPath(const std::string& name) {
  return std::string(AUTOGRAV_BINARY_DIR) + "/image_compare_test_" + name;
}

TEST(ImageCompareTest, IdenticalImagesPass) {
  RgbImage a = filled(64, 48, 255, 255, 255);
  paintRect(a, 10, 10, 20, 5, 30, 120, 200);
  const ImageComparison result = compareImages(a, a);
  EXPECT_TRUE(result.same_size);
  EXPECT_TRUE(result.passed);
  EXPECT_EQ(result.differing_pixels, 0);
  EXPECT_DOUBLE_EQ(result.differing_fraction, 0.0);
  EXPECT_DOUBLE_EQ(result.mean_abs_difference, 0.0);
  EXPECT_EQ(result.max_channel_difference, 0);
}

TEST(ImageCompareTest, EdgeMovedByOnePixelIsForgiven) {
  RgbImage expected = filled(64, 48, 255, 255, 255);
  RgbImage actual = expected;
  paintRect(expected, 10, 10, 20, 6, 0, 0, 0);
  paintRect(actual, 11, 10, 20, 6, 0, 0, 0);  // the rasterizer put the edges one pixel right
  const ImageComparison forgiving = compareImages(actual, expected);
  EXPECT_EQ(forgiving.differing_pixels, 0);
  EXPECT_EQ(forgiving.max_channel_difference, 255);
  EXPECT_TRUE(forgiving.passed);
  // Without the neighbourhood search both edge columns count: 2 columns of 6 pixels.
  ImageComparisonOptions strict;
  strict.search_radius_px = 0;
  const ImageComparison plain = compareImages(actual, expected, strict);
  EXPECT_EQ(plain.differing_pixels, 12);
  EXPECT_NEAR(plain.differing_fraction, 12.0 / (64 * 48), 1e-15);
}

TEST(ImageCompareTest, SlightShadeChangeIsBelowThreshold) {
  const RgbImage expected = filled(40, 30, 100, 150, 200);
  const RgbImage actual = filled(40, 30, 103, 150, 198);
  const ImageComparison result = compareImages(actual, expected);
  EXPECT_EQ(result.differing_pixels, 0);
  EXPECT_TRUE(result.passed);
  EXPECT_NEAR(result.mean_abs_difference, (3.0 + 0.0 + 2.0) / 3.0, 1e-12);
  EXPECT_EQ(result.max_channel_difference, 3);
}

TEST(ImageCompareTest, MissingBlobCountsEveryPixelAndMarksTheDiff) {
  RgbImage expected = filled(100, 80, 255, 255, 255);
  paintRect(expected, 40, 30, 10, 10, 200, 20, 20);
  const RgbImage actual = filled(100, 80, 255, 255, 255);
  RgbImage diff;
  const ImageComparison result = compareImages(actual, expected, {}, &diff);
  EXPECT_EQ(result.differing_pixels, 100);
  EXPECT_NEAR(result.differing_fraction, 100.0 / 8000.0, 1e-15);
  EXPECT_FALSE(result.passed);
  ASSERT_EQ(diff.width_px, 100);
  ASSERT_EQ(diff.height_px, 80);
  const std::uint8_t* marked = diff.pixel(45, 35);
  EXPECT_EQ(marked[0], 230);
  EXPECT_EQ(marked[1], 0);
  EXPECT_EQ(marked[2], 0);
  // Elsewhere the expected picture, faded: white stays near white.
  const std::uint8_t* faded = diff.pixel(5, 5);
  EXPECT_EQ(faded[0], 191 + 255 / 4);
}

TEST(ImageCompareTest, ToleranceDecides) {
  RgbImage expected = filled(100, 100, 255, 255, 255);
  RgbImage actual = expected;
  paintRect(actual, 0, 0, 3, 3, 0, 0, 0);  // 9 of 10000 pixels
  ImageComparisonOptions options;
  options.tolerance = 1e-3;
  EXPECT_TRUE(compareImages(actual, expected, options).passed);
  options.tolerance = 5e-4;
  EXPECT_FALSE(compareImages(actual, expected, options).passed);
}

TEST(ImageCompareTest, DifferentSizesFail) {
  const ImageComparison result = compareImages(filled(10, 10, 0, 0, 0), filled(10, 12, 0, 0, 0));
  EXPECT_FALSE(result.same_size);
  EXPECT_FALSE(result.passed);
  EXPECT_EQ(result.actual_height_px, 10);
  EXPECT_EQ(result.height_px, 12);
  EXPECT_NE(describe(result, {}).find("10x10 px rendered, 10x12 px expected"), std::string::npos);
}

TEST(ImageCompareTest, RejectsBadOptionsAndEmptyImages) {
  const RgbImage a = filled(4, 4, 0, 0, 0);
  ImageComparisonOptions options;
  options.tolerance = -0.1;
  EXPECT_THROW(compareImages(a, a, options), Error);
  options = {};
  options.channel_threshold = 300;
  EXPECT_THROW(compareImages(a, a, options), Error);
  options = {};
  options.search_radius_px = -1;
  EXPECT_THROW(compareImages(a, a, options), Error);
  EXPECT_THROW(compareImages(RgbImage{}, a), Error);
}

TEST(ImageCompareTest, DescribeGivesTheNumbers) {
  RgbImage expected = filled(100, 100, 255, 255, 255);
  RgbImage actual = expected;
  paintRect(actual, 0, 0, 5, 4, 0, 0, 0);
  const ImageComparisonOptions options;
  const std::string text = describe(compareImages(actual, expected, options), options);
  EXPECT_NE(text.find("0.2000% of pixels differ (20 px)"), std::string::npos) << text;
  EXPECT_NE(text.find("OVER tolerance 0.0050%"), std::string::npos) << text;
}

TEST(PngTest, RoundTripKeepsEveryPixel) {
  RgbImage image = filled(33, 17, 10, 20, 30);
  paintRect(image, 3, 2, 5, 7, 250, 128, 1);
  image.pixel(32, 16)[1] = 77;  // the bottom-right corner: catches a flipped row order
  const std::string path = scratchPath("roundtrip.png");
  writePng(image, path);
  const RgbImage back = readPng(path);
  EXPECT_EQ(back.width_px, 33);
  EXPECT_EQ(back.height_px, 17);
  EXPECT_EQ(back.rgb, image.rgb);
  std::remove(path.c_str());
}

TEST(PngTest, CompareFilesWritesTheDiff) {
  RgbImage expected = filled(50, 40, 255, 255, 255);
  RgbImage actual = expected;
  paintRect(actual, 20, 20, 4, 4, 0, 0, 255);
  const std::string a = scratchPath("a.png");
  const std::string e = scratchPath("e.png");
  const std::string d = scratchPath("d.png");
  writePng(actual, a);
  writePng(expected, e);
  const ImageComparison result = compareImageFiles(a, e, {}, d);
  EXPECT_EQ(result.differing_pixels, 16);
  const RgbImage diff = readPng(d);
  EXPECT_EQ(diff.pixel(21, 21)[0], 230);
  for (const auto& path : {a, e, d}) std::remove(path.c_str());
}

TEST(PngTest, ErrorsNameTheFile) {
  try {
    readPng("/nonexistent/folder/picture.png");
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/folder/picture.png"), std::string::npos);
  }
  const std::string text_file = scratchPath("not_a_png.png");
  std::ofstream(text_file) << "hello";
  try {
    readPng(text_file);
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("not a PNG"), std::string::npos) << error.what();
  }
  std::remove(text_file.c_str());
  EXPECT_THROW(writePng(filled(4, 4, 0, 0, 0), "/nonexistent/folder/out.png"), Error);
  EXPECT_THROW(writePng(RgbImage{}, scratchPath("empty.png")), Error);
}

}  // namespace
}  // namespace autograv::viz
