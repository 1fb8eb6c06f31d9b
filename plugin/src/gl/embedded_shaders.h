#pragma once

#include <cstddef>

namespace autograv::gl::detail {

/// One GLSL file of shaders/, embedded at build time by embed_shaders.cmake.
struct EmbeddedShader {
  const char* name;    ///< File name, e.g. "mesh.vert".
  const char* source;  ///< The file's text.
};

extern const EmbeddedShader kEmbeddedShaders[];
extern const std::size_t kEmbeddedShaderCount;

}  // namespace autograv::gl::detail
