#include "gl/gl_functions.h"

#include <string>

#include "autograv/error.h"

namespace autograv::gl::detail {

void GlFunctions::load(GlProcLoader loader) {
  if (loader == nullptr) throw Error("GL: no function loader for this context");
#define AUTOGRAV_GL_LOAD(type, name)                                                            \
  name = reinterpret_cast<type>(loader("gl" #name));                                            \
  if (name == nullptr) {                                                                        \
    throw Error("GL: the context does not provide gl" #name                                     \
                "; OpenGL 3.3 core is needed (with Mesa: libosmesa6 or a 3.3-capable driver)"); \
  }
  AUTOGRAV_GL_FUNCTION_LIST(AUTOGRAV_GL_LOAD)
#undef AUTOGRAV_GL_LOAD
}

void contextVersion(const GlFunctions& gl, int& major, int& minor) {
  major = 0;
  minor = 0;
  gl.GetIntegerv(GL_MAJOR_VERSION, &major);
  gl.GetIntegerv(GL_MINOR_VERSION, &minor);
}

}  // namespace autograv::gl::detail
