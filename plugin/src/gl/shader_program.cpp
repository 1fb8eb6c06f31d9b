#include "gl/shader_program.h"

#include <sys/stat.h>
#include <fstream>
#include <regex>
#include <sstream>

#include "autograv/error.h"
#include "gl/embedded_shaders.h"

namespace autograv::gl::detail {

namespace {

constexpr int kMaxIncludeDepth = 8;

bool isDirectory(const std::string& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode);
}

std::string trimLeft(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  return first == std::string::npos ? std::string() : text.substr(first);
}

}  // namespace

ShaderLibrary ShaderLibrary::embedded() { return ShaderLibrary("", "embedded"); }

ShaderLibrary ShaderLibrary::fromDirectory(const std::string& directory) {
  if (!isDirectory(directory)) {
    throw Error("shader folder '" + directory +
                "' does not exist; point it at the project's shaders/ folder or leave it empty to "
                "use the shaders embedded at build time");
  }
  return ShaderLibrary(directory, directory);
}

std::string ShaderLibrary::displayPath(const std::string& name) const {
  if (directory_.empty()) return "shaders/" + name + " (embedded)";
  return directory_ + "/" + name;
}

std::string ShaderLibrary::source(const std::string& name) const {
  if (directory_.empty()) {
    for (std::size_t i = 0; i < kEmbeddedShaderCount; ++i) {
      if (name == kEmbeddedShaders[i].name) return kEmbeddedShaders[i].source;
    }
    throw Error("shader '" + name + "' is not among the shaders embedded at build time");
  }
  std::ifstream file(displayPath(name), std::ios::binary);
  if (!file) throw Error("cannot read shader file " + displayPath(name));
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

ShaderLibrary::Expanded ShaderLibrary::expand(const std::string& name) const {
  Expanded out;
  expandInto(name, 0, out);
  return out;
}

void ShaderLibrary::expandInto(const std::string& name, int depth, Expanded& out) const {
  if (depth > kMaxIncludeDepth) {
    throw Error(displayPath(name) + ": includes nest deeper than " +
                std::to_string(kMaxIncludeDepth) + " levels (circular #include?)");
  }
  const int index = static_cast<int>(out.files.size());
  out.files.push_back(displayPath(name));
  std::istringstream lines(source(name));
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::string trimmed = trimLeft(line);
    if (trimmed.rfind("#include", 0) != 0) {
      if (depth > 0 && trimmed.rfind("#version", 0) == 0) {
        throw Error(displayPath(name) + ":" + std::to_string(line_number) +
                    ": an included file must not have a #version line");
      }
      out.text += line;
      out.text += '\n';
      continue;
    }
    const auto open = trimmed.find('"');
    const auto close = open == std::string::npos ? open : trimmed.find('"', open + 1);
    if (close == std::string::npos || close == open + 1) {
      throw Error(displayPath(name) + ":" + std::to_string(line_number) +
                  ": expected #include \"file.glsl\"");
    }
    const std::string included = trimmed.substr(open + 1, close - open - 1);
    // "#line L S": the next line is line L of source string S (GLSL 3.30 and later).
    out.text += "#line 1 " + std::to_string(out.files.size()) + "\n";
    expandInto(included, depth + 1, out);
    out.text += "#line " + std::to_string(line_number + 1) + " " + std::to_string(index) + "\n";
  }
}

std::string annotateInfoLog(const std::string& log, const std::vector<std::string>& files) {
  // Mesa: "0:12(5): error: ..."; NVIDIA: "0(12) : error C0000: ..."; AMD: "ERROR: 0:12: ...".
  static const std::regex mesa(R"(^(\d+):(\d+)\((\d+)\): (.*)$)");
  static const std::regex nvidia(R"(^(\d+)\((\d+)\) ?: (.*)$)");
  static const std::regex amd(R"(^(ERROR|WARNING): (\d+):(\d+): (.*)$)");
  const auto fileName = [&files](const std::string& number) {
    const auto index = std::stoul(number);
    return index < files.size() ? files[index] : "<source string " + number + ">";
  };
  std::istringstream lines(log);
  std::string line;
  std::string out;
  std::smatch match;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (std::regex_match(line, match, mesa)) {
      out +=
          fileName(match[1]) + ":" + match[2].str() + ":" + match[3].str() + ": " + match[4].str();
    } else if (std::regex_match(line, match, nvidia)) {
      out += fileName(match[1]) + ":" + match[2].str() + ": " + match[3].str();
    } else if (std::regex_match(line, match, amd)) {
      out +=
          fileName(match[2]) + ":" + match[3].str() + ": " + match[1].str() + ": " + match[4].str();
    } else {
      out += line;
    }
    out += '\n';
  }
  return out;
}

ShaderProgram::ShaderProgram(const GlFunctions& gl, const ShaderLibrary& library,
                             const std::string& vertex_name, const std::string& fragment_name)
    : gl_(gl) {
  const GLuint vertex = compile(GL_VERTEX_SHADER, library, vertex_name);
  GLuint fragment = 0;
  try {
    fragment = compile(GL_FRAGMENT_SHADER, library, fragment_name);
  } catch (...) {
    gl_.DeleteShader(vertex);
    throw;
  }
  program_ = gl_.CreateProgram();
  gl_.AttachShader(program_, vertex);
  gl_.AttachShader(program_, fragment);
  gl_.LinkProgram(program_);
  gl_.DeleteShader(vertex);  // Flagged for deletion; freed with the program.
  gl_.DeleteShader(fragment);
  GLint linked = GL_FALSE;
  gl_.GetProgramiv(program_, GL_LINK_STATUS, &linked);
  if (linked != GL_TRUE) {
    GLint length = 0;
    gl_.GetProgramiv(program_, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(length > 1 ? length : 1), '\0');
    gl_.GetProgramInfoLog(program_, static_cast<GLsizei>(log.size()), nullptr, log.data());
    gl_.DeleteProgram(program_);
    throw Error("GLSL link error in the program " + library.displayPath(vertex_name) + " + " +
                library.displayPath(fragment_name) + ":\n" + log.c_str());
  }
}

ShaderProgram::~ShaderProgram() {
  if (program_ != 0) gl_.DeleteProgram(program_);
}

GLint ShaderProgram::uniform(const char* name) const {
  return gl_.GetUniformLocation(program_, name);
}

void ShaderProgram::use() const { gl_.UseProgram(program_); }

GLuint ShaderProgram::compile(GLenum stage, const ShaderLibrary& library,
                              const std::string& name) const {
  const ShaderLibrary::Expanded expanded = library.expand(name);
  const GLuint shader = gl_.CreateShader(stage);
  const char* text = expanded.text.c_str();
  gl_.ShaderSource(shader, 1, &text, nullptr);
  gl_.CompileShader(shader);
  GLint compiled = GL_FALSE;
  gl_.GetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
  if (compiled == GL_TRUE) return shader;
  GLint length = 0;
  gl_.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(length > 1 ? length : 1), '\0');
  gl_.GetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
  gl_.DeleteShader(shader);
  throw Error("GLSL compile error in " + library.displayPath(name) + ":\n" +
              annotateInfoLog(log.c_str(), expanded.files));
}

}  // namespace autograv::gl::detail
