#include "autograv/image/image_comparison.h"

#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/image/png.h"
#include "test_images.h"

namespace autograv::testing {
namespace {

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
  EXPECT_EQ(result.actual_size.height_px, 10);
  EXPECT_EQ(result.expected_size.height_px, 12);
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

TEST(PngTest, CompareFilesWritesTheDiff) {
  RgbImage expected = filled(50, 40, 255, 255, 255);
  RgbImage actual = expected;
  paintRect(actual, 20, 20, 4, 4, 0, 0, 255);
  const std::string a = scratchPath("a.png");
  const std::string e = scratchPath("e.png");
  const std::string d = scratchPath("d.png");
  writePng(actual, a, PngEncoding::kPlain);
  writePng(expected, e, PngEncoding::kPlain);
  const ImageComparison result = compareImageFiles(a, e, {}, d);
  EXPECT_EQ(result.differing_pixels, 16);
  const RgbImage diff = readPng(d);
  EXPECT_EQ(diff.pixel(21, 21)[0], 230);
  for (const auto& path : {a, e, d}) std::remove(path.c_str());
}

// Without a search radius every pixel beyond the threshold counts: the real-time renderer's tests.
TEST(ImageCompareTest, WithoutSearchRadiusEveryPixelBeyondTheThresholdCounts) {
  const RgbImage a = gradient(10, 10);
  RgbImage b = a;
  b.rgb[0] = static_cast<std::uint8_t>(b.rgb[0] + 50);                    // one pixel far off
  b.rgb[3 * 55 + 2] = static_cast<std::uint8_t>(b.rgb[3 * 55 + 2] + 10);  // one slightly off
  ImageComparisonOptions options;
  options.search_radius_px = 0;
  options.channel_threshold = 20;
  const ImageComparison loose = compareImages(a, b, options);
  EXPECT_EQ(loose.differing_pixels, 1);
  EXPECT_DOUBLE_EQ(loose.differing_fraction, 0.01);
  EXPECT_EQ(loose.max_channel_difference, 50);
  options.channel_threshold = 5;
  EXPECT_EQ(compareImages(a, b, options).differing_pixels, 2);
  options.channel_threshold = 0;
  EXPECT_EQ(compareImages(a, a, options).differing_pixels, 0);
}

}  // namespace
}  // namespace autograv::testing
