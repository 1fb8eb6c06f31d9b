#include "autograv/gl/image.h"

#include <png.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "autograv/error.h"
#include "autograv/map/map_io.h"

namespace autograv::gl {

namespace {

struct FileCloser {
  void operator()(std::FILE* file) const {
    if (file != nullptr) std::fclose(file);
  }
};
using FilePointer = std::unique_ptr<std::FILE, FileCloser>;

void checkSameSize(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) {
    throw Error("images differ in size: " + std::to_string(a.width) + "x" +
                std::to_string(a.height) + " against " + std::to_string(b.width) + "x" +
                std::to_string(b.height));
  }
}

int largestChannelDifference(const Image& a, const Image& b, std::size_t pixel) {
  int largest = 0;
  for (int c = 0; c < 3; ++c) {
    largest = std::max(largest, std::abs(static_cast<int>(a.rgb[3 * pixel + c]) -
                                         static_cast<int>(b.rgb[3 * pixel + c])));
  }
  return largest;
}

}  // namespace

void writePng(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw Error("cannot write " + path + ": the image is empty or its buffer has the wrong size");
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // Encode in memory, then write atomically like maps and reports: a reader (or a crash) never
  // sees half a picture.
  png_alloc_size_t size = 0;
  if (png_image_write_get_memory_size(png, size, 0, image.rgb.data(), 0, nullptr) == 0) {
    throw Error("cannot write PNG " + path + ": " + png.message);
  }
  std::string encoded(size, '\0');
  if (png_image_write_to_memory(&png, encoded.data(), &size, 0, image.rgb.data(), 0, nullptr) ==
      0) {
    throw Error("cannot write PNG " + path + ": " + png.message);
  }
  encoded.resize(size);
  writeFileAtomically(path, encoded, "PNG");
}

Image readPng(const std::string& path) {
  FilePointer file(std::fopen(path.c_str(), "rb"));
  if (!file) throw Error("cannot open PNG " + path + ": no such file or not readable");
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_stdio(&png, file.get()) == 0) {
    throw Error("cannot read PNG " + path + ": " + png.message);
  }
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr) == 0) {
    throw Error("cannot read PNG " + path + ": " + png.message);
  }
  return image;
}

ImageDifference compareImages(const Image& a, const Image& b, int threshold) {
  checkSameSize(a, b);
  ImageDifference difference;
  const std::size_t pixels = static_cast<std::size_t>(a.width) * a.height;
  for (std::size_t p = 0; p < pixels; ++p) {
    const int largest = largestChannelDifference(a, b, p);
    difference.max_channel_difference = std::max(difference.max_channel_difference, largest);
    if (largest > threshold) ++difference.pixels_differing;
  }
  difference.fraction_differing =
      pixels == 0 ? 0.0
                  : static_cast<double>(difference.pixels_differing) / static_cast<double>(pixels);
  return difference;
}

Image differenceImage(const Image& a, const Image& b, int threshold) {
  checkSameSize(a, b);
  Image out = a;
  const std::size_t pixels = static_cast<std::size_t>(a.width) * a.height;
  for (std::size_t p = 0; p < pixels; ++p) {
    if (largestChannelDifference(a, b, p) > threshold) {
      out.rgb[3 * p + 0] = 255;
      out.rgb[3 * p + 1] = 0;
      out.rgb[3 * p + 2] = 0;
    } else {
      for (int c = 0; c < 3; ++c)
        out.rgb[3 * p + c] = static_cast<std::uint8_t>(a.rgb[3 * p + c] / 3);
    }
  }
  return out;
}

}  // namespace autograv::gl
