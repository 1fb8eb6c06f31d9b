#include "autograv/image/png.h"

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "autograv/error.h"
#include "autograv/map/map_io.h"

namespace autograv {

namespace {

// zlib level of PngEncoding::kPlain; kSrgbTagged keeps libpng's default.
constexpr int kPlainZlibLevel = 5;
constexpr std::size_t kSignatureBytes = 8;

// Bytes in or out of libpng, and the message of the error that stopped it (libpng reports
// errors by longjmp, so the message waits here for the exception thrown afterwards).
struct PngStream {
  std::string bytes;
  std::size_t read_offset = 0;
  char error[256] = {};
};

void onError(png_structp png, png_const_charp message) {
  auto* stream = static_cast<PngStream*>(png_get_error_ptr(png));
  std::snprintf(stream->error, sizeof stream->error, "%s", message);
  png_longjmp(png, 1);
}

void onWarning(png_structp, png_const_charp) {}  // not fatal; the picture is read all the same

void appendBytes(png_structp png, png_bytep data, png_size_t length) {
  static_cast<PngStream*>(png_get_io_ptr(png))
      ->bytes.append(reinterpret_cast<const char*>(data), length);
}

void flushNothing(png_structp) {}

void readBytes(png_structp png, png_bytep data, png_size_t length) {
  auto* stream = static_cast<PngStream*>(png_get_io_ptr(png));
  if (stream->bytes.size() - stream->read_offset < length) png_error(png, "the file ends early");
  std::copy_n(stream->bytes.data() + stream->read_offset, length, data);
  stream->read_offset += length;
}

// The libpng calls of one encoding, apart so that the frame of setjmp holds nothing to destroy.
bool encodeRows(png_structp png, png_infop info, const RgbImage& image, PngEncoding encoding,
                png_bytep* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  if (encoding == PngEncoding::kPlain) png_set_compression_level(png, kPlainZlibLevel);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width_px),
               static_cast<png_uint_32>(image.height_px), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (encoding == PngEncoding::kSrgbTagged) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

std::string encode(const RgbImage& image, PngEncoding encoding, const std::string& subject) {
  if (!image.consistent()) {
    throw Error(subject + ": nothing to write (empty or inconsistent image)");
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.height_px));
  for (int y = 0; y < image.height_px; ++y) {
    rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(image.pixel(0, y));
  }
  PngStream stream;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &stream, onError, onWarning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  bool encoded = false;
  if (info != nullptr) {
    png_set_write_fn(png, &stream, appendBytes, flushNothing);
    encoded = encodeRows(png, info, image, encoding, rows.data());
  }
  png_destroy_write_struct(&png, &info);
  if (!encoded) {
    throw Error(subject + ": PNG encoding failed" +
                (stream.error[0] != '\0' ? " (" + std::string(stream.error) + ")" : ""));
  }
  return std::move(stream.bytes);
}

// A decoded PNG as libpng hands it over after its transformations: 3 samples a pixel, 1 or 2
// bytes a sample.
struct DecodedRows {
  int width_px = 0;
  int height_px = 0;
  int bit_depth = 8;
  std::vector<png_byte> samples;
  std::vector<png_bytep> rows;
};

// The libpng calls of one decoding, apart so that the frame of setjmp holds nothing to destroy.
bool decodeRows(png_structp png, png_infop info, DecodedRows& decoded) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  png_set_palette_to_rgb(png);
  png_set_expand_gray_1_2_4_to_8(png);
  png_set_gray_to_rgb(png);
  png_set_strip_alpha(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  decoded.width_px = static_cast<int>(png_get_image_width(png, info));
  decoded.height_px = static_cast<int>(png_get_image_height(png, info));
  decoded.bit_depth = png_get_bit_depth(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  decoded.samples.resize(row_bytes * static_cast<std::size_t>(decoded.height_px));
  decoded.rows.resize(static_cast<std::size_t>(decoded.height_px));
  for (std::size_t y = 0; y < decoded.rows.size(); ++y) {
    decoded.rows[y] = decoded.samples.data() + y * row_bytes;
  }
  png_read_image(png, decoded.rows.data());
  png_read_end(png, nullptr);
  return true;
}

}  // namespace

std::string encodePng(const RgbImage& image, PngEncoding encoding) {
  return encode(image, encoding, "image");
}

void writePng(const RgbImage& image, const std::string& path, PngEncoding encoding) {
  writeFileAtomically(path, encode(image, encoding, "image " + path), "image");
}

RgbImage readPng(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("image " + path + ": cannot open the file for reading (does it exist?)");
  PngStream stream;
  stream.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (stream.bytes.size() < kSignatureBytes ||
      png_sig_cmp(reinterpret_cast<png_const_bytep>(stream.bytes.data()), 0, kSignatureBytes) !=
          0) {
    throw Error("image " + path + ": not a PNG file (the PNG signature is missing)");
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &stream, onError, onWarning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  DecodedRows decoded;
  bool read = false;
  if (info != nullptr) {
    png_set_read_fn(png, &stream, readBytes);
    read = decodeRows(png, info, decoded);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!read) {
    throw Error("image " + path + ": cannot decode the PNG" +
                (stream.error[0] != '\0' ? " (" + std::string(stream.error) + ")" : ""));
  }
  RgbImage image;
  image.width_px = decoded.width_px;
  image.height_px = decoded.height_px;
  image.rgb.resize(static_cast<std::size_t>(image.width_px) * image.height_px * 3);
  if (decoded.bit_depth == 8) {
    std::copy(decoded.samples.begin(), decoded.samples.end(), image.rgb.begin());
    return image;
  }
  // 16-bit samples (big-endian in the file) to the nearest 8-bit value.
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    const double value = (decoded.samples[2 * i] << 8 | decoded.samples[2 * i + 1]) * (1.0 / 257.0);
    image.rgb[i] = static_cast<std::uint8_t>(std::clamp(value + 0.5, 0.0, 255.0));
  }
  return image;
}

}  // namespace autograv
