#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace autograv::gl {

/// An 8-bit RGB picture, rows top to bottom (the order of PNG files and of the screen).
struct Image {
  int width = 0;                  ///< Unit: [px]
  int height = 0;                 ///< Unit: [px]
  std::vector<std::uint8_t> rgb;  ///< width * height * 3 bytes, row-major from the top row.

  /// Pixel (x, y) from the top-left corner; channel 0..2 = red, green, blue.
  std::uint8_t at(int x, int y, int channel) const {
    return rgb[(static_cast<std::size_t>(y) * width + x) * 3 + channel];
  }
};

/// Writes `image` as an 8-bit RGB PNG. Throws autograv::Error naming the path when the file cannot
/// be written. Not real-time safe.
void writePng(const Image& image, const std::string& path);

/// Reads an 8-bit or 16-bit PNG of any colour type into RGB (alpha is dropped, grey expanded).
/// Throws autograv::Error naming the path when the file is missing or not a PNG. Not real-time
/// safe.
Image readPng(const std::string& path);

/// How two pictures of the same size differ.
struct ImageDifference {
  /// Fraction of pixels whose largest channel difference exceeds the threshold, in [0, 1].
  double fraction_differing = 0.0;
  /// Largest channel difference over the whole picture, 0..255.
  int max_channel_difference = 0;
  /// Number of pixels counted in fraction_differing.
  long long pixels_differing = 0;
};

/// Compares two pictures pixel by pixel: a pixel differs when any channel differs by more than
/// `threshold` (0..255). Throws autograv::Error when the sizes differ. Not real-time safe.
ImageDifference compareImages(const Image& a, const Image& b, int threshold);

/// A picture showing where `a` and `b` differ (differing pixels red over a dimmed `a`), to look at
/// when a screenshot test fails. Throws autograv::Error when the sizes differ. Not real-time safe.
Image differenceImage(const Image& a, const Image& b, int threshold);

}  // namespace autograv::gl
