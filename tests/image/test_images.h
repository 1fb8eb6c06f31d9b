#pragma once

// Small pictures made in code for the tests of autograv::image.

#include <cstdint>
#include <string>

#include "autograv/image/rgb_image.h"

namespace autograv::testing {

/// Paints the `w` x `h` rectangle at (x0, y0) of `image` in one colour.
inline void paintRect(RgbImage& image, int x0, int y0, int w, int h, std::uint8_t r, std::uint8_t g,
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

/// A `width` x `height` picture of one colour.
inline RgbImage filled(int width, int height, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  RgbImage image;
  image.width_px = width;
  image.height_px = height;
  image.rgb.resize(static_cast<std::size_t>(width) * height * 3);
  paintRect(image, 0, 0, width, height, r, g, b);
  return image;
}

/// Red growing to the right, green growing downward, blue constant: every pixel differs from
/// its neighbours, so a flipped or shifted row shows.
inline RgbImage gradient(int width, int height) {
  RgbImage image = filled(width, height, 0, 0, 77);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.pixel(x, y)[0] = static_cast<std::uint8_t>(x * 255 / (width - 1));
      image.pixel(x, y)[1] = static_cast<std::uint8_t>(y * 255 / (height - 1));
    }
  }
  return image;
}

/// A file of the build folder for a test's scratch picture.
inline std::string scratchPath(const std::string& name) {
  return std::string(AUTOGRAV_BINARY_DIR) + "/image_test_" + name;
}

}  // namespace autograv::testing
