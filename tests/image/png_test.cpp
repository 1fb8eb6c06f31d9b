// The one PNG codec of the scene, the plots and the real-time renderer: pixels survive a round
// trip, each encoding keeps the bytes its pictures have always had, any PNG reads as RGB.
#include "autograv/image/png.h"

#include <png.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "test_images.h"

namespace autograv::testing {
namespace {

std::string fileBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

// The chunk types of a PNG file, in order.
std::vector<std::string> chunkTypes(const std::string& bytes) {
  std::vector<std::string> types;
  for (std::size_t at = 8; at + 8 <= bytes.size();) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(bytes[at + i]); };
    const std::size_t length =
        static_cast<std::size_t>(byte(0)) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3);
    types.push_back(bytes.substr(at + 4, 4));
    at += 12 + length;
  }
  return types;
}

// Writes `samples` (rows from the top, `channels` samples a pixel) as a PNG of another colour
// type or bit depth than the codec writes, with libpng's simplified writer.
std::string writeOtherPng(const std::string& name, int width, int height, png_uint_32 format,
                          const std::vector<png_uint_16>& samples) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(width);
  png.height = static_cast<png_uint_32>(height);
  png.format = format;
  const std::string path = scratchPath(name);
  std::vector<png_byte> bytes;
  const void* buffer = samples.data();
  if ((format & PNG_FORMAT_FLAG_LINEAR) == 0) {
    bytes.assign(samples.begin(), samples.end());
    buffer = bytes.data();
  }
  EXPECT_NE(png_image_write_to_file(&png, path.c_str(), 0, buffer, 0, nullptr), 0) << png.message;
  return path;
}

TEST(PngTest, RoundTripKeepsEveryPixelInBothEncodings) {
  RgbImage image = gradient(33, 17);
  paintRect(image, 3, 2, 5, 7, 250, 128, 1);
  image.pixel(32, 16)[1] = 7;  // the bottom-right corner: catches a flipped row order
  for (const PngEncoding encoding : {PngEncoding::kPlain, PngEncoding::kSrgbTagged}) {
    const std::string path = scratchPath("roundtrip.png");
    writePng(image, path, encoding);
    EXPECT_EQ(fileBytes(path), encodePng(image, encoding));
    const RgbImage back = readPng(path);
    EXPECT_EQ(back.width_px, 33);
    EXPECT_EQ(back.height_px, 17);
    EXPECT_EQ(back.rgb, image.rgb);
    std::remove(path.c_str());
  }
}

TEST(PngTest, TheEncodingsDifferInTheirChunks) {
  const RgbImage image = gradient(16, 9);
  EXPECT_EQ(chunkTypes(encodePng(image, PngEncoding::kPlain)),
            (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  EXPECT_EQ(chunkTypes(encodePng(image, PngEncoding::kSrgbTagged)),
            (std::vector<std::string>{"IHDR", "sRGB", "IDAT", "IEND"}));
}

// The goldens of tests/visual were written by the encodings as they were before there was one
// codec (VTK's writer for the scene and plots, libpng's simplified writer for the renderer):
// decoded and encoded again, each gives back its file byte for byte.
TEST(PngTest, EveryGoldenKeepsItsBytes) {
  const std::string folder = std::string(AUTOGRAV_SOURCE_DIR) + "/tests/visual/golden/";
  const char* scene_and_plots[] = {"falcon_explored_front_dark_residual.png",
                                   "falcon_explored_iso.png",
                                   "omega_convergence.png",
                                   "omega_iso.png",
                                   "omega_top_residual.png",
                                   "omni_front_dark.png",
                                   "omni_summary.png"};
  const char* screenshots[] = {"gl_demo_headless.png", "gl_scene.png", "gl_workspace.png"};
  for (const char* name : scene_and_plots) {
    const std::string path = folder + name;
    EXPECT_EQ(encodePng(readPng(path), PngEncoding::kPlain), fileBytes(path)) << name;
  }
  for (const char* name : screenshots) {
    const std::string path = folder + name;
    EXPECT_EQ(encodePng(readPng(path), PngEncoding::kSrgbTagged), fileBytes(path)) << name;
  }
}

TEST(PngTest, GreyAlphaAndSixteenBitFilesReadAsRgb) {
  // Grey: repeated into R, G and B.
  RgbImage back = readPng(writeOtherPng("grey.png", 2, 1, PNG_FORMAT_GRAY, {10, 200}));
  EXPECT_EQ(back.rgb, (std::vector<std::uint8_t>{10, 10, 10, 200, 200, 200}));
  // Grey with alpha and RGBA: the alpha is dropped, not blended.
  back = readPng(writeOtherPng("grey_alpha.png", 1, 1, PNG_FORMAT_GA, {90, 0}));
  EXPECT_EQ(back.rgb, (std::vector<std::uint8_t>{90, 90, 90}));
  back = readPng(writeOtherPng("rgba.png", 1, 1, PNG_FORMAT_RGBA, {1, 2, 3, 128}));
  EXPECT_EQ(back.rgb, (std::vector<std::uint8_t>{1, 2, 3}));
  // 16 bits: each sample to the nearest 8-bit value.
  back = readPng(
      writeOtherPng("sixteen.png", 1, 1, PNG_FORMAT_LINEAR_RGB, {0, 257 * 100 + 128, 65535}));
  EXPECT_EQ(back.rgb, (std::vector<std::uint8_t>{0, 100, 255}));
}

TEST(PngTest, ErrorsNameTheFile) {
  try {
    readPng("/nonexistent/folder/picture.png");
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/folder/picture.png"), std::string::npos);
  }
  const std::string text_file = scratchPath("not_a_png.png");
  std::ofstream(text_file) << "hello";
  try {
    readPng(text_file);
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("not a PNG"), std::string::npos) << error.what();
  }
  // A PNG cut short: the signature is there, the rest is not.
  const std::string cut_file = scratchPath("cut.png");
  const std::string whole = encodePng(gradient(8, 8), PngEncoding::kPlain);
  std::ofstream(cut_file, std::ios::binary) << whole.substr(0, whole.size() / 2);
  try {
    readPng(cut_file);
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("cannot decode"), std::string::npos) << error.what();
  }
  for (const auto& path : {text_file, cut_file}) std::remove(path.c_str());
  EXPECT_THROW(writePng(filled(4, 4, 0, 0, 0), "/nonexistent/folder/out.png", PngEncoding::kPlain),
               Error);
  EXPECT_THROW(writePng(RgbImage{}, scratchPath("empty.png"), PngEncoding::kPlain), Error);
  EXPECT_THROW(encodePng(RgbImage{}, PngEncoding::kSrgbTagged), Error);
}

}  // namespace
}  // namespace autograv::testing
