#pragma once

#include <memory>

#include "autograv/gl/gl_context.h"
#include "autograv/image/rgb_image.h"

namespace autograv::gl {

/// An OpenGL 3.3 core context drawing into memory through OSMesa: no X server, no display, no GPU.
/// Used by headless runs and screenshot tests.
class OffscreenContext final : public GlContext {
 public:
  /// Creates the context and its colour/depth buffer. Throws autograv::Error when OSMesa cannot
  /// give a 3.3 core context or the size is not in [1, 8192]. Not real-time safe.
  OffscreenContext(int width_px, int height_px);
  ~OffscreenContext() override;
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  void makeCurrent() override;
  int framebufferWidth() const override;
  /// Height of the offscreen framebuffer. Unit: [px]
  int framebufferHeight() const override;
  GlProcLoader procLoader() const override;

  /// Waits for the GL to finish and returns what was drawn. The context must be current on the
  /// calling thread. Not real-time safe.
  RgbImage readImage();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace autograv::gl
