#pragma once

#include <string>

#include "autograv/image/png.h"
#include "autograv/image/rgb_image.h"

namespace autograv::viz {

/// Writes a picture of this library (a scene, a plot) as a PNG file in the bytes its files have
/// always had: autograv::writePng with PngEncoding::kPlain. Throws autograv::Error naming the
/// file when the image is empty or the file cannot be written. Not real-time safe.
inline void writePng(const RgbImage& image, const std::string& path) {
  autograv::writePng(image, path, PngEncoding::kPlain);
}

}  // namespace autograv::viz
