#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace autograv {

/// An 8-bit RGB image, rows from top to bottom as in a PNG file and on the screen. What the VTK
/// scene and plots (autograv::viz) and the real-time renderer (autograv::gl) both draw into.
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
  /// True when the image has no pixel. Real-time safe.
  bool empty() const noexcept { return width_px <= 0 || height_px <= 0; }
  /// True when the image has pixels and `rgb` holds exactly 3 bytes for each. Real-time safe.
  bool consistent() const noexcept {
    return !empty() && rgb.size() == static_cast<std::size_t>(width_px) * height_px * 3;
  }
};

}  // namespace autograv
