#include "autograv/gl/offscreen_context.h"

#include <GL/osmesa.h>

#include <string>
#include <vector>

#include "autograv/error.h"

namespace autograv::gl {

namespace {
constexpr int kMaxSide = 8192;
using FinishFunction = void (*)();
}  // namespace

struct OffscreenContext::State {
  OSMesaContext context = nullptr;
  int width = 0;
  int height = 0;
  std::vector<unsigned char> pixels;  // RGBA, bottom row first (OSMesa's default).
};

OffscreenContext::OffscreenContext(int width_px, int height_px)
    : state_(std::make_unique<State>()) {
  if (width_px < 1 || width_px > kMaxSide || height_px < 1 || height_px > kMaxSide) {
    throw Error("offscreen size " + std::to_string(width_px) + "x" + std::to_string(height_px) +
                " is not in [1, " + std::to_string(kMaxSide) + "] pixels per side");
  }
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_STENCIL_BITS,
                            0,
                            OSMESA_ACCUM_BITS,
                            0,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  state_->context = OSMesaCreateContextAttribs(attributes, nullptr);
  if (state_->context == nullptr) {
    throw Error(
        "OSMesa could not create an OpenGL 3.3 core context; install libosmesa6 (Mesa 17 or "
        "later) and make sure it is Mesa's llvmpipe build");
  }
  state_->width = width_px;
  state_->height = height_px;
  state_->pixels.assign(static_cast<std::size_t>(width_px) * height_px * 4, 0);
  makeCurrent();
}

OffscreenContext::~OffscreenContext() {
  if (state_->context != nullptr) OSMesaDestroyContext(state_->context);
}

void OffscreenContext::makeCurrent() {
  if (!OSMesaMakeCurrent(state_->context, state_->pixels.data(), GL_UNSIGNED_BYTE, state_->width,
                         state_->height)) {
    throw Error("OSMesa refused to make the offscreen context current");
  }
}

int OffscreenContext::framebufferWidth() const { return state_->width; }
int OffscreenContext::framebufferHeight() const { return state_->height; }

GlProcLoader OffscreenContext::procLoader() const {
  return reinterpret_cast<GlProcLoader>(&OSMesaGetProcAddress);
}

RgbImage OffscreenContext::readImage() {
  const auto finish = reinterpret_cast<FinishFunction>(OSMesaGetProcAddress("glFinish"));
  if (finish != nullptr) finish();
  RgbImage image;
  image.width_px = state_->width;
  image.height_px = state_->height;
  image.rgb.resize(static_cast<std::size_t>(image.width_px) * image.height_px * 3);
  for (int y = 0; y < image.height_px; ++y) {
    const unsigned char* source =
        state_->pixels.data() +
        static_cast<std::size_t>(image.height_px - 1 - y) * image.width_px * 4;
    std::uint8_t* target = image.rgb.data() + static_cast<std::size_t>(y) * image.width_px * 3;
    for (int x = 0; x < image.width_px; ++x) {
      target[3 * x + 0] = source[4 * x + 0];
      target[3 * x + 1] = source[4 * x + 1];
      target[3 * x + 2] = source[4 * x + 2];
    }
  }
  return image;
}

}  // namespace autograv::gl
