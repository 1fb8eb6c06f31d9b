#pragma once

#include <string>

#include "autograv/image/rgb_image.h"

namespace autograv {

/// How two renders are compared. The defaults survive the rounding differences of a software
/// rasterizer (llvmpipe: edges moved by a pixel, a slightly different shade) and still catch a
/// missing arrow, another colour map or a moved camera.
struct ImageComparisonOptions {
  /// A pixel differs when its largest channel difference exceeds this, on a 0-255 scale.
  int channel_threshold = 40;
  /// A pixel is forgiven when some pixel of the other image within this many pixels (in x and
  /// y) matches it within channel_threshold: edges that moved by a pixel do not count. 0 counts
  /// every pixel beyond the threshold, as the real-time renderer's screenshot tests do.
  int search_radius_px = 1;
  /// The comparison passes when the fraction of differing pixels is at most this.
  double tolerance = 5.0e-5;
};

/// The size of a picture.
struct ImageSize {
  /// Width. Unit: [px]
  int width_px = 0;
  /// Height. Unit: [px]
  int height_px = 0;
};

/// The outcome of a comparison of two images.
struct ImageComparison {
  /// True when the two images have the same size (nothing else is compared otherwise).
  bool same_size = false;
  /// Size of the expected image.
  ImageSize expected_size;
  /// Size of the actual image.
  ImageSize actual_size;
  /// Pixels that differ in either direction after forgiving one-pixel shifts.
  long differing_pixels = 0;
  /// differing_pixels / (width_px * height_px) of the expected image; 1 when the sizes differ.
  double differing_fraction = 1.0;
  /// same_size and differing_fraction <= tolerance.
  bool passed = false;
  /// Mean absolute difference over all pixels and channels, plain (no shift forgiven), 0-255.
  double mean_abs_difference = 0.0;
  /// Largest channel difference of any pixel, plain, 0-255.
  int max_channel_difference = 0;
};

/// Compares `actual` with `expected`. When `diff` is given it receives a picture of the
/// difference: the expected image faded to light grey, differing pixels in red. Throws
/// autograv::Error on negative options. Not real-time safe.
ImageComparison compareImages(const RgbImage& actual, const RgbImage& expected,
                              const ImageComparisonOptions& options = {}, RgbImage* diff = nullptr);

/// compareImages on two PNG files; writes the difference picture to `diff_png` when it is not
/// empty (PngEncoding::kPlain). Throws autograv::Error naming a file that cannot be read or
/// written. Not real-time safe.
ImageComparison compareImageFiles(const std::string& actual_png, const std::string& expected_png,
                                  const ImageComparisonOptions& options = {},
                                  const std::string& diff_png = "");

/// One line for logs, e.g. "0.0312% of pixels differ (96 px), mean |diff| 0.41, max 255:
/// within tolerance 0.02%". Not real-time safe.
std::string describe(const ImageComparison& comparison, const ImageComparisonOptions& options);

}  // namespace autograv
