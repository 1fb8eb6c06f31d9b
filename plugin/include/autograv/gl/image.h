#pragma once

#include <string>

#include "autograv/image/png.h"
#include "autograv/image/rgb_image.h"

namespace autograv::gl {

/// Writes a screenshot of the renderer as a PNG file in the bytes its files have always had:
/// autograv::writePng with PngEncoding::kSrgbTagged. Throws autograv::Error naming the file when
/// the image is empty or the file cannot be written. Not real-time safe.
inline void writePng(const RgbImage& image, const std::string& path) {
  autograv::writePng(image, path, PngEncoding::kSrgbTagged);
}

}  // namespace autograv::gl
