#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace autograv::viz {

/// An 8-bit RGB image, rows from top to bottom as in a PNG file.
struct RgbImage {
  /// Width. Unit: [px]
  int width_px = 0;
  /// Height. Unit: [px]
  int height_px = 0;
  /// width_px * height_px * 3 bytes: R, G, B of each pixel, row by row from the top.
  std::vector<std::uint8_t> rgb;

  /// Pointer to the 3 bytes of pixel (x, y), y counted from the top row. No bounds check.
  /// Real-time safe.
  const std::uint8_t* pixel(int x, int y) const noexcept {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * width_px + x);
  }
  /// Pointer to the 3 bytes of pixel (x, y), writable. No bounds check. Real-time safe.
  std::uint8_t* pixel(int x, int y) noexcept {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * width_px + x);
  }
  /// Real-time safe.
  bool empty() const noexcept { return width_px <= 0 || height_px <= 0; }
};

/// Reads a PNG file (grey, grey+alpha, RGB or RGBA; alpha is dropped). Throws autograv::Error
/// naming the file when it is missing or not a readable PNG. Not real-time safe.
RgbImage readPng(const std::string& path);

/// Writes `image` as a PNG file. Throws autograv::Error naming the file when the image is empty
/// or the file cannot be written. Not real-time safe.
void writePng(const RgbImage& image, const std::string& path);

}  // namespace autograv::viz
