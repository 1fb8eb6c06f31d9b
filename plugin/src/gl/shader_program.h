#pragma once

#include <string>
#include <vector>

#include "gl/gl_functions.h"

namespace autograv::gl::detail {

/// The project's GLSL files by name ("mesh.vert"), read from a folder (for editing shaders without
/// rebuilding) or from the copies embedded at build time. A file may pull in another with a line
/// `#include "name.glsl"`; expand() resolves it and keeps the line numbers of every file.
class ShaderLibrary {
 public:
  /// The copies embedded at build time.
  static ShaderLibrary embedded();
  /// Files read from `directory` when asked for. Throws autograv::Error when it is not a folder.
  static ShaderLibrary fromDirectory(const std::string& directory);

  /// "embedded" or the folder.
  const std::string& origin() const { return origin_; }
  /// How `name` is called in messages: its path, or "shaders/<name> (embedded)".
  std::string displayPath(const std::string& name) const;
  /// The text of `name`. Throws autograv::Error naming the file when it does not exist.
  std::string source(const std::string& name) const;

  /// A file with its includes resolved; GLSL source-string number i (in `#line L i` and in the
  /// compiler's messages) is the file files[i].
  struct Expanded {
    std::string text;
    std::vector<std::string> files;
  };
  /// Throws autograv::Error for a missing file, a malformed or circular include.
  Expanded expand(const std::string& name) const;

 private:
  ShaderLibrary(std::string directory, std::string origin)
      : directory_(std::move(directory)), origin_(std::move(origin)) {}
  void expandInto(const std::string& name, int depth, Expanded& out) const;

  std::string directory_;  ///< Empty for the embedded copies.
  std::string origin_;
};

/// Rewrites a GLSL info log so that each message names its file and line: Mesa's "1:12(5): error:"
/// and NVIDIA's "1(12) : error" become "<files[1]>:12: error:". Other lines are kept as they are.
std::string annotateInfoLog(const std::string& log, const std::vector<std::string>& files);

/// A linked vertex + fragment program. Compile and link errors throw autograv::Error whose
/// message gives the file and line of every error the driver reported.
class ShaderProgram {
 public:
  ShaderProgram(const GlFunctions& gl, const ShaderLibrary& library, const std::string& vertex_name,
                const std::string& fragment_name);
  ~ShaderProgram();
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  GLuint id() const { return program_; }
  /// Location of a uniform; -1 when the linker dropped it (glUniform ignores -1).
  GLint uniform(const char* name) const;
  void use() const;

 private:
  GLuint compile(GLenum stage, const ShaderLibrary& library, const std::string& name) const;

  const GlFunctions& gl_;
  GLuint program_ = 0;
};

}  // namespace autograv::gl::detail
