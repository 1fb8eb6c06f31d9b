// The project's shaders compile and link under OSMesa, embedded or read from shaders/, and a
// broken shader is reported with its file and line.
#include "gl/shader_program.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "autograv/error.h"
#include "autograv/gl/offscreen_context.h"
#include "autograv/gl/renderer.h"
#include "scratch_folder.h"

namespace autograv::gl::detail {
namespace {

const std::string kShaderDir = std::string(AUTOGRAV_SOURCE_DIR) + "/shaders";

/// A scratch folder of shader files (autograv-shaders-XXXXXX).
class ScratchShaders {
 public:
  void write(const std::string& name, const std::string& text) {
    std::ofstream(folder_.file(name)) << text;
  }
  std::string directory() const { return folder_.path().string(); }

 private:
  autograv::testing::ScratchFolder folder_{"shaders"};
};

const char* const kGoodVertex =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_position;\n"
    "out vec3 v_position;\n"
    "void main() {\n"
    "  v_position = a_position;\n"
    "  gl_Position = vec4(a_position, 1.0);\n"
    "}\n";

class ShaderProgramTest : public ::testing::Test {
 protected:
  ShaderProgramTest() : context_(16, 16) { gl_.load(context_.procLoader()); }

  /// The message of the autograv::Error that building the program throws ("" when none).
  std::string buildError(const ShaderLibrary& library, const std::string& vertex,
                         const std::string& fragment) {
    try {
      ShaderProgram program(gl_, library, vertex, fragment);
    } catch (const Error& error) {
      return error.what();
    }
    return "";
  }

  OffscreenContext context_;
  GlFunctions gl_;
};

TEST_F(ShaderProgramTest, EveryEmbeddedProgramCompilesAndLinks) {
  const ShaderLibrary library = ShaderLibrary::embedded();
  for (const auto& [vertex, fragment] :
       std::vector<std::pair<std::string, std::string>>{{"lines.vert", "lines.frag"},
                                                        {"mesh.vert", "mesh.frag"},
                                                        {"overlay.vert", "overlay.frag"}}) {
    ShaderProgram program(gl_, library, vertex, fragment);
    EXPECT_NE(program.id(), 0u) << vertex;
  }
  EXPECT_EQ(gl_.GetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(ShaderProgramTest, ProgramsFromTheSourceFolderCompileAndLink) {
  const ShaderLibrary library = ShaderLibrary::fromDirectory(kShaderDir);
  ShaderProgram mesh(gl_, library, "mesh.vert", "mesh.frag");
  EXPECT_GE(mesh.uniform("u_view_projection"), 0);
  EXPECT_GE(mesh.uniform("u_eye_m"), 0);
  ShaderProgram overlay(gl_, library, "overlay.vert", "overlay.frag");
  EXPECT_GE(overlay.uniform("u_font"), 0);
}

TEST_F(ShaderProgramTest, EmbeddedCopiesEqualTheSourceFiles) {
  const ShaderLibrary embedded = ShaderLibrary::embedded();
  const ShaderLibrary files = ShaderLibrary::fromDirectory(kShaderDir);
  const std::vector<std::string> names = embeddedShaderNames();
  EXPECT_EQ(names.size(), 7u);
  for (const std::string& name : names)
    EXPECT_EQ(embedded.source(name), files.source(name)) << name;
}

TEST_F(ShaderProgramTest, SyntaxErrorIsReportedWithFileAndLine) {
  ScratchShaders scratch;
  scratch.write("good.vert", kGoodVertex);
  scratch.write("broken.frag",
                "#version 330 core\n"        // 1
                "in vec3 v_position;\n"      // 2
                "out vec4 o_color;\n"        // 3
                "void main() {\n"            // 4
                "  vec3 c = v_position;\n"   // 5
                "  float k = 2.0\n"          // 6: missing ';' ...
                "  o_color = vec4(c, k);\n"  // 7: ... found here
                "}\n");
  const std::string message =
      buildError(ShaderLibrary::fromDirectory(scratch.directory()), "good.vert", "broken.frag");
  EXPECT_NE(message.find("GLSL compile error"), std::string::npos) << message;
  EXPECT_NE(message.find(scratch.directory() + "/broken.frag:7:"), std::string::npos) << message;
}

TEST_F(ShaderProgramTest, ErrorInAnIncludedFileNamesThatFile) {
  ScratchShaders scratch;
  scratch.write("good.vert", kGoodVertex);
  scratch.write("helpers.glsl",
                "// helpers\n"                       // 1
                "vec3 tint(vec3 c) {\n"              // 2
                "  return c * undeclared_factor;\n"  // 3
                "}\n");
  scratch.write("uses_helpers.frag",
                "#version 330 core\n"
                "#include \"helpers.glsl\"\n"
                "in vec3 v_position;\n"
                "out vec4 o_color;\n"
                "void main() { o_color = vec4(tint(v_position), 1.0); }\n");
  const std::string message = buildError(ShaderLibrary::fromDirectory(scratch.directory()),
                                         "good.vert", "uses_helpers.frag");
  EXPECT_NE(message.find(scratch.directory() + "/helpers.glsl:3:"), std::string::npos) << message;
}

TEST_F(ShaderProgramTest, LinesAfterAnIncludeKeepTheirNumbers) {
  ScratchShaders scratch;
  scratch.write("good.vert", kGoodVertex);
  scratch.write("one.glsl", "float one() { return 1.0; }\n");
  scratch.write("late_error.frag",
                "#version 330 core\n"                   // 1
                "#include \"one.glsl\"\n"               // 2
                "out vec4 o_color;\n"                   // 3
                "void main() {\n"                       // 4
                "  o_color = vec4(one()) + nothing;\n"  // 5
                "}\n");
  const std::string message =
      buildError(ShaderLibrary::fromDirectory(scratch.directory()), "good.vert", "late_error.frag");
  EXPECT_NE(message.find(scratch.directory() + "/late_error.frag:5:"), std::string::npos)
      << message;
}

TEST_F(ShaderProgramTest, LinkErrorNamesBothFiles) {
  ScratchShaders scratch;
  scratch.write("good.vert", kGoodVertex);
  // Reads v_position as a vec4 where the vertex shader writes a vec3: each compiles alone, the
  // pair fails to link.
  scratch.write("unmatched.frag",
                "#version 330 core\n"
                "in vec4 v_position;\n"
                "out vec4 o_color;\n"
                "void main() { o_color = v_position; }\n");
  const std::string message =
      buildError(ShaderLibrary::fromDirectory(scratch.directory()), "good.vert", "unmatched.frag");
  EXPECT_NE(message.find("GLSL link error"), std::string::npos) << message;
  EXPECT_NE(message.find("good.vert"), std::string::npos) << message;
  EXPECT_NE(message.find("unmatched.frag"), std::string::npos) << message;
}

TEST(ShaderLibraryTest, MissingFileAndFolderAreReportedByName) {
  EXPECT_THROW(ShaderLibrary::fromDirectory("/nonexistent/shaders"), Error);
  const ShaderLibrary library = ShaderLibrary::fromDirectory(kShaderDir);
  try {
    library.source("nope.frag");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(kShaderDir + "/nope.frag"), std::string::npos);
  }
  EXPECT_THROW(ShaderLibrary::embedded().source("nope.frag"), Error);
}

TEST(ShaderLibraryTest, CircularAndMalformedIncludesAreRefused) {
  ScratchShaders scratch;
  scratch.write("a.glsl", "#include \"b.glsl\"\n");
  scratch.write("b.glsl", "#include \"a.glsl\"\n");
  scratch.write("bad.glsl", "// one\n#include helpers.glsl\n");
  const ShaderLibrary library = ShaderLibrary::fromDirectory(scratch.directory());
  EXPECT_THROW(library.expand("a.glsl"), Error);
  try {
    library.expand("bad.glsl");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("bad.glsl:2"), std::string::npos) << error.what();
  }
}

TEST(ShaderLibraryTest, ExpandNumbersEveryFile) {
  const ShaderLibrary library = ShaderLibrary::fromDirectory(kShaderDir);
  const ShaderLibrary::Expanded expanded = library.expand("mesh.vert");
  ASSERT_EQ(expanded.files.size(), 2u);
  EXPECT_EQ(expanded.files[0], kShaderDir + "/mesh.vert");
  EXPECT_EQ(expanded.files[1], kShaderDir + "/colormap.glsl");
  EXPECT_NE(expanded.text.find("#line 1 1\n"), std::string::npos);
  EXPECT_EQ(expanded.text.find("#include"), std::string::npos);
  EXPECT_EQ(expanded.text.rfind("#version 330 core", 0), 0u);
}

TEST(AnnotateInfoLogTest, RewritesMesaNvidiaAndAmdFormats) {
  const std::vector<std::string> files = {"main.frag", "colormap.glsl"};
  const std::string out = annotateInfoLog(
      "0:12(5): error: syntax error, unexpected IDENTIFIER\n"
      "1(3) : error C1008: undefined variable \"x\"\n"
      "ERROR: 1:4: 'y' : undeclared identifier\n"
      "plain driver text\n",
      files);
  EXPECT_NE(out.find("main.frag:12:5: error: syntax error"), std::string::npos) << out;
  EXPECT_NE(out.find("colormap.glsl:3: error C1008"), std::string::npos) << out;
  EXPECT_NE(out.find("colormap.glsl:4: ERROR: 'y'"), std::string::npos) << out;
  EXPECT_NE(out.find("plain driver text"), std::string::npos) << out;
  EXPECT_NE(annotateInfoLog("7:1(1): error: x\n", files).find("<source string 7>:1:1"),
            std::string::npos);
}

}  // namespace
}  // namespace autograv::gl::detail
