#pragma once

#include <cstdint>
#include <string>

#include "autograv/image/rgb_image.h"

namespace autograv {

/// The bytes an 8-bit RGB PNG of given pixels is written as. Both hold the same pixels and read
/// back alike; each kind of picture keeps the bytes it has always had, so that its goldens and
/// the hashes of its files do not move.
enum class PngEncoding : std::uint8_t {
  /// IHDR, IDAT and IEND only, zlib level 5: the scene and the plots of autograv::viz (the bytes
  /// VTK's PNG writer made for them).
  kPlain,
  /// An sRGB chunk (perceptual intent) besides, zlib's default level: the screenshots of
  /// autograv::gl (the bytes libpng's simplified writer made for them).
  kSrgbTagged,
};

/// `image` as the bytes of a PNG file. Throws autograv::Error when the image is empty or its
/// buffer has the wrong size. Not real-time safe.
std::string encodePng(const RgbImage& image, PngEncoding encoding);

/// Writes `image` as a PNG file, atomically (a reader, or a crash, never sees half a picture).
/// Throws autograv::Error naming the file when the image is empty or the file cannot be written.
/// Not real-time safe.
void writePng(const RgbImage& image, const std::string& path, PngEncoding encoding);

/// Reads a PNG file of any colour type and bit depth: grey is repeated into R, G and B, a
/// palette is expanded, alpha is dropped, 16-bit samples are rounded to 8 bits. Throws
/// autograv::Error naming the file when it is missing or not a readable PNG.
/// Not real-time safe.
RgbImage readPng(const std::string& path);

}  // namespace autograv
