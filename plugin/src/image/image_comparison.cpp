#include "autograv/image/image_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "autograv/error.h"
#include "autograv/image/png.h"

namespace autograv {

namespace {

int channelDistance(const std::uint8_t* a, const std::uint8_t* b) noexcept {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

// True when no pixel of `other` within `radius` of (x, y) matches `image`'s pixel (x, y).
bool unmatched(const RgbImage& image, const RgbImage& other, int x, int y, int radius,
               int threshold) noexcept {
  const std::uint8_t* here = image.pixel(x, y);
  const int x0 = std::max(0, x - radius);
  const int x1 = std::min(other.width_px - 1, x + radius);
  const int y0 = std::max(0, y - radius);
  const int y1 = std::min(other.height_px - 1, y + radius);
  for (int yy = y0; yy <= y1; ++yy) {
    for (int xx = x0; xx <= x1; ++xx) {
      if (channelDistance(here, other.pixel(xx, yy)) <= threshold) return false;
    }
  }
  return true;
}

void checkImage(const RgbImage& image, const char* which) {
  if (!image.consistent()) {
    throw Error(std::string("image comparison: the ") + which + " image is empty or inconsistent");
  }
}

}  // namespace

ImageComparison compareImages(const RgbImage& actual, const RgbImage& expected,
                              const ImageComparisonOptions& options, RgbImage* diff) {
  if (options.channel_threshold < 0 || options.channel_threshold > 255) {
    throw Error("image comparison: channel threshold must be within 0..255");
  }
  if (options.search_radius_px < 0 || options.search_radius_px > 16) {
    throw Error("image comparison: search radius must be within 0..16 px");
  }
  if (!std::isfinite(options.tolerance) || options.tolerance < 0.0 || options.tolerance > 1.0) {
    throw Error("image comparison: tolerance must be a fraction of pixels within 0..1");
  }
  checkImage(actual, "actual");
  checkImage(expected, "expected");

  ImageComparison result;
  result.expected_size = {expected.width_px, expected.height_px};
  result.actual_size = {actual.width_px, actual.height_px};
  result.same_size = actual.width_px == expected.width_px && actual.height_px == expected.height_px;
  if (diff != nullptr) {
    // The expected picture, faded so that the red marks stand out.
    *diff = expected;
    for (auto& value : diff->rgb) value = static_cast<std::uint8_t>(191 + value / 4);
  }
  if (!result.same_size) return result;

  const int width = expected.width_px;
  const int height = expected.height_px;
  double sum = 0.0;
  long differing = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::uint8_t* a = actual.pixel(x, y);
      const std::uint8_t* b = expected.pixel(x, y);
      for (int c = 0; c < 3; ++c) sum += std::abs(a[c] - b[c]);
      const int distance = channelDistance(a, b);
      result.max_channel_difference = std::max(result.max_channel_difference, distance);
      if (distance <= options.channel_threshold) continue;
      // Forgive edges that moved by a pixel: look for a match nearby, both ways.
      if (unmatched(actual, expected, x, y, options.search_radius_px, options.channel_threshold) ||
          unmatched(expected, actual, x, y, options.search_radius_px, options.channel_threshold)) {
        ++differing;
        if (diff != nullptr) {
          std::uint8_t* mark = diff->pixel(x, y);
          mark[0] = 230;
          mark[1] = 0;
          mark[2] = 0;
        }
      }
    }
  }
  const double pixels = static_cast<double>(width) * height;
  result.differing_pixels = differing;
  result.differing_fraction = static_cast<double>(differing) / pixels;
  result.mean_abs_difference = sum / (3.0 * pixels);
  result.passed = result.differing_fraction <= options.tolerance;
  return result;
}

ImageComparison compareImageFiles(const std::string& actual_png, const std::string& expected_png,
                                  const ImageComparisonOptions& options,
                                  const std::string& diff_png) {
  const RgbImage actual = readPng(actual_png);
  const RgbImage expected = readPng(expected_png);
  RgbImage diff;
  const ImageComparison result =
      compareImages(actual, expected, options, diff_png.empty() ? nullptr : &diff);
  if (!diff_png.empty()) writePng(diff, diff_png, PngEncoding::kPlain);
  return result;
}

std::string describe(const ImageComparison& comparison, const ImageComparisonOptions& options) {
  std::ostringstream text;
  if (!comparison.same_size) {
    text << "image sizes differ: " << comparison.actual_size.width_px << "x"
         << comparison.actual_size.height_px << " px rendered, "
         << comparison.expected_size.width_px << "x" << comparison.expected_size.height_px
         << " px expected";
    return text.str();
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "%.4f%% of pixels differ (%ld px), mean |diff| %.3f, max %d: %s tolerance %.4f%%",
                100.0 * comparison.differing_fraction, comparison.differing_pixels,
                comparison.mean_abs_difference, comparison.max_channel_difference,
                comparison.passed ? "within" : "OVER", 100.0 * options.tolerance);
  return line;
}

}  // namespace autograv
