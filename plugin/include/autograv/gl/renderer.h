#pragma once

#include <memory>
#include <string>
#include <vector>

#include "autograv/gl/frame_data.h"
#include "autograv/gl/gl_context.h"

namespace autograv::gl {

/// Settings of the Renderer, fixed at construction.
struct RendererOptions {
  /// Folder to read the GLSL files from (shaders/ of the source tree, for editing shaders without
  /// rebuilding). Empty: the environment variable AUTOGRAV_SHADER_DIR if set, else the copies
  /// embedded at build time.
  std::string shader_directory;
};

/// Draws a Scene with OpenGL 3.3 core and the project's GLSL shaders: the grid lattice, instanced
/// arrows for the gravity map coloured by magnitude, the end-effector with its trail, the force
/// being sent, and a text readout in a bitmap font of our own. The same class draws into a window
/// or an offscreen buffer.
class Renderer {
 public:
  /// Makes `context` current, loads the GL functions, compiles and links every program. Throws
  /// autograv::Error when the context is older than 3.3 or a shader fails (the message names the
  /// file and line). `context` must outlive the renderer. Not real-time safe.
  explicit Renderer(GlContext& context, const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws one frame over the whole framebuffer of the context (which must be current on the
  /// calling thread). Not real-time safe.
  void render(const Scene& scene);

  /// "4.5 (Core Profile) Mesa 22.3.6" and the like.
  const std::string& glVersion() const;
  /// Where the shaders came from: a folder path or "embedded".
  const std::string& shaderOrigin() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Names of the GLSL files embedded at build time ("mesh.vert", ...). Not real-time safe.
std::vector<std::string> embeddedShaderNames();

}  // namespace autograv::gl
