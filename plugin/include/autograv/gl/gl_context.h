#pragma once

namespace autograv::gl {

/// A GL entry point as the platform loaders return it (OSMesaGetProcAddress, glfwGetProcAddress).
using GlProc = void (*)();
/// Looks up a GL entry point by name ("glDrawArrays"); returns null when it does not exist.
using GlProcLoader = GlProc (*)(const char* name);

/// A surface with an OpenGL 3.3+ core context that a Renderer can draw into: a GLFW window or an
/// OSMesa offscreen buffer. Contexts are bound to one thread at a time (the one that made them
/// current), like every OpenGL context.
class GlContext {
 public:
  virtual ~GlContext() = default;
  /// Makes this context current on the calling thread. Throws autograv::Error when the platform
  /// refuses. Not real-time safe.
  virtual void makeCurrent() = 0;
  /// Size of the drawable in pixels (the framebuffer, not screen coordinates). Unit: [px]
  virtual int framebufferWidth() const = 0;
  /// See framebufferWidth(). Unit: [px]
  virtual int framebufferHeight() const = 0;
  /// The loader for this context's GL functions. Not real-time safe.
  virtual GlProcLoader procLoader() const = 0;
};

}  // namespace autograv::gl
