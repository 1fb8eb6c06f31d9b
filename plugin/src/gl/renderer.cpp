#include "autograv/gl/renderer.h"

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "autograv/error.h"
#include "gl/embedded_shaders.h"
#include "gl/font.h"
#include "gl/frame_lists.h"
#include "gl/gl_functions.h"
#include "gl/meshes.h"
#include "gl/shader_program.h"

namespace autograv::gl {

using detail::GlFunctions;
using detail::LineVertex;
using detail::MeshData;
using detail::MeshInstance;
using detail::MeshVertex;
using detail::OverlayQuad;
using detail::ShaderLibrary;
using detail::ShaderProgram;

namespace {

constexpr float kBackground[3] = {0.085f, 0.095f, 0.115f};
constexpr int kArrowSegments = 18;
constexpr int kSphereSlices = 24;
constexpr int kSphereStacks = 14;

/// A static mesh with its own per-instance buffer.
struct InstancedMesh {
  /// Deletes the GL objects (a name never made is 0, which GL skips).
  void destroy(GlFunctions& gl);

  GLuint vao = 0;
  GLuint vertex_buffer = 0;
  GLuint index_buffer = 0;
  GLuint instance_buffer = 0;
  GLsizei index_count = 0;
};

void InstancedMesh::destroy(GlFunctions& gl) {
  if (vao != 0) gl.DeleteVertexArrays(1, &vao);
  const GLuint buffers[] = {vertex_buffer, index_buffer, instance_buffer};
  gl.DeleteBuffers(3, buffers);
}

/// The line list's vertex array and its buffer.
struct LineObjects {
  GLuint vao = 0;
  GLuint buffer = 0;
};

Eigen::Matrix4f toFloat(const Eigen::Matrix4d& m) { return m.cast<float>(); }

/// The overlay's vertex array, its corner and instance buffers, and the font's texture.
struct OverlayObjects {
  GLuint vao = 0;
  GLuint corner_buffer = 0;
  GLuint instance_buffer = 0;
  GLuint font_texture = 0;
};

}  // namespace

struct Renderer::State {
  explicit State(GlContext& c) : context(c) {}

  GlContext& context;
  GlFunctions gl;
  std::string version;
  std::string shader_origin;
  std::unique_ptr<ShaderProgram> lines_program;
  std::unique_ptr<ShaderProgram> mesh_program;
  std::unique_ptr<ShaderProgram> overlay_program;

  LineObjects line;
  InstancedMesh arrow;
  InstancedMesh sphere;
  OverlayObjects overlay;

  // What the frame draws, built on the CPU (frame_content.cpp, frame_overlay.cpp).
  detail::FrameLists frame;

  void createLineBuffers();
  void createMesh(InstancedMesh& mesh, const MeshData& data);
  void createOverlay();
  void destroy();

  void drawLines(const Eigen::Matrix4f& view_projection);
  void drawMesh(InstancedMesh& mesh, const std::vector<MeshInstance>& instances, bool colormap,
                const Eigen::Matrix4f& view_projection, const Eigen::Vector3d& eye);
  void drawOverlay(int width, int height);
};

void Renderer::State::createLineBuffers() {
  gl.GenVertexArrays(1, &line.vao);
  gl.GenBuffers(1, &line.buffer);
  gl.BindVertexArray(line.vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, line.buffer);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                         reinterpret_cast<const void*>(offsetof(LineVertex, position)));
  gl.EnableVertexAttribArray(1);
  gl.VertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                         reinterpret_cast<const void*>(offsetof(LineVertex, color)));
  gl.BindVertexArray(0);
}

void Renderer::State::createMesh(InstancedMesh& mesh, const MeshData& data) {
  gl.GenVertexArrays(1, &mesh.vao);
  gl.GenBuffers(1, &mesh.vertex_buffer);
  gl.GenBuffers(1, &mesh.index_buffer);
  gl.GenBuffers(1, &mesh.instance_buffer);
  gl.BindVertexArray(mesh.vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, mesh.vertex_buffer);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.vertices.size() * sizeof(MeshVertex)),
                data.vertices.data(), GL_STATIC_DRAW);
  const auto attribute = [this](GLuint index, GLint size, GLsizei stride, std::size_t offset,
                                GLuint divisor) {
    gl.EnableVertexAttribArray(index);
    gl.VertexAttribPointer(index, size, GL_FLOAT, GL_FALSE, stride,
                           reinterpret_cast<const void*>(offset));
    gl.VertexAttribDivisor(index, divisor);
  };
  attribute(0, 3, sizeof(MeshVertex), offsetof(MeshVertex, local), 0);
  attribute(1, 3, sizeof(MeshVertex), offsetof(MeshVertex, normal), 0);
  attribute(2, 2, sizeof(MeshVertex), offsetof(MeshVertex, along), 0);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.index_buffer);
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER,
                static_cast<GLsizeiptr>(data.indices.size() * sizeof(std::uint32_t)),
                data.indices.data(), GL_STATIC_DRAW);
  gl.BindBuffer(GL_ARRAY_BUFFER, mesh.instance_buffer);
  attribute(3, 3, sizeof(MeshInstance), offsetof(MeshInstance, origin), 1);
  attribute(4, 4, sizeof(MeshInstance), offsetof(MeshInstance, direction), 1);
  attribute(5, 2, sizeof(MeshInstance), offsetof(MeshInstance, size), 1);
  attribute(6, 4, sizeof(MeshInstance), offsetof(MeshInstance, color), 1);
  gl.BindVertexArray(0);
  mesh.index_count = static_cast<GLsizei>(data.indices.size());
}

void Renderer::State::createOverlay() {
  const float corners[] = {0, 0, 1, 0, 0, 1, 1, 1};
  gl.GenVertexArrays(1, &overlay.vao);
  gl.GenBuffers(1, &overlay.corner_buffer);
  gl.GenBuffers(1, &overlay.instance_buffer);
  gl.BindVertexArray(overlay.vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay.corner_buffer);
  gl.BufferData(GL_ARRAY_BUFFER, sizeof(corners), corners, GL_STATIC_DRAW);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay.instance_buffer);
  const auto attribute = [this](GLuint index, GLint size, std::size_t offset) {
    gl.EnableVertexAttribArray(index);
    gl.VertexAttribPointer(index, size, GL_FLOAT, GL_FALSE, sizeof(OverlayQuad),
                           reinterpret_cast<const void*>(offset));
    gl.VertexAttribDivisor(index, 1);
  };
  attribute(1, 4, offsetof(OverlayQuad, rect));
  attribute(2, 4, offsetof(OverlayQuad, color));
  attribute(3, 1, offsetof(OverlayQuad, kind));
  gl.BindVertexArray(0);

  const detail::FontAtlas atlas = detail::buildFontAtlas();
  gl.GenTextures(1, &overlay.font_texture);
  gl.BindTexture(GL_TEXTURE_2D, overlay.font_texture);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_R8, atlas.width, atlas.height, 0, GL_RED, GL_UNSIGNED_BYTE,
                atlas.texels.data());
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  gl.BindTexture(GL_TEXTURE_2D, 0);
}

void Renderer::State::destroy() {
  arrow.destroy(gl);
  sphere.destroy(gl);
  if (line.vao != 0) gl.DeleteVertexArrays(1, &line.vao);
  if (overlay.vao != 0) gl.DeleteVertexArrays(1, &overlay.vao);
  const GLuint buffers[] = {line.buffer, overlay.corner_buffer, overlay.instance_buffer};
  gl.DeleteBuffers(3, buffers);
  if (overlay.font_texture != 0) gl.DeleteTextures(1, &overlay.font_texture);
}

void Renderer::State::drawLines(const Eigen::Matrix4f& view_projection) {
  const std::vector<LineVertex>& line_vertices = frame.lines;
  if (line_vertices.empty()) return;
  lines_program->use();
  gl.UniformMatrix4fv(lines_program->uniform("u_view_projection"), 1, GL_FALSE,
                      view_projection.data());
  gl.BindVertexArray(line.vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, line.buffer);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(line_vertices.size() * sizeof(LineVertex)),
                line_vertices.data(), GL_STREAM_DRAW);
  gl.DrawArrays(GL_LINES, 0, static_cast<GLsizei>(line_vertices.size()));
  gl.BindVertexArray(0);
}

void Renderer::State::drawMesh(InstancedMesh& mesh, const std::vector<MeshInstance>& instances,
                               bool colormap, const Eigen::Matrix4f& view_projection,
                               const Eigen::Vector3d& eye) {
  if (instances.empty()) return;
  mesh_program->use();
  gl.UniformMatrix4fv(mesh_program->uniform("u_view_projection"), 1, GL_FALSE,
                      view_projection.data());
  gl.Uniform3f(mesh_program->uniform("u_eye_m"), static_cast<float>(eye.x()),
               static_cast<float>(eye.y()), static_cast<float>(eye.z()));
  gl.Uniform1i(mesh_program->uniform("u_use_colormap"), colormap ? 1 : 0);
  gl.BindVertexArray(mesh.vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, mesh.instance_buffer);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(instances.size() * sizeof(MeshInstance)),
                instances.data(), GL_STREAM_DRAW);
  gl.DrawElementsInstanced(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr,
                           static_cast<GLsizei>(instances.size()));
  gl.BindVertexArray(0);
}

void Renderer::State::drawOverlay(int width, int height) {
  const std::vector<OverlayQuad>& overlay_quads = frame.overlay;
  if (overlay_quads.empty()) return;
  overlay_program->use();
  gl.Uniform2f(overlay_program->uniform("u_viewport_px"), static_cast<float>(width),
               static_cast<float>(height));
  gl.Uniform1i(overlay_program->uniform("u_font"), 0);
  gl.Uniform1i(overlay_program->uniform("u_font_columns"), detail::kAtlasColumns);
  gl.Uniform2i(overlay_program->uniform("u_cell_texels"), detail::kCellWidth, detail::kCellHeight);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D, overlay.font_texture);
  gl.BindVertexArray(overlay.vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay.instance_buffer);
  gl.BufferData(GL_ARRAY_BUFFER,
                static_cast<GLsizeiptr>(overlay_quads.size() * sizeof(OverlayQuad)),
                overlay_quads.data(), GL_STREAM_DRAW);
  gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(overlay_quads.size()));
  gl.BindVertexArray(0);
}

Renderer::Renderer(GlContext& context, const RendererOptions& options)
    : state_(std::make_unique<State>(context)) {
  State& s = *state_;
  context.makeCurrent();
  s.gl.load(context.procLoader());
  int major = 0;
  int minor = 0;
  detail::contextVersion(s.gl, major, minor);
  const auto* version = reinterpret_cast<const char*>(s.gl.GetString(GL_VERSION));
  s.version = version != nullptr ? version : "unknown";
  if (major < 3 || (major == 3 && minor < 3)) {
    throw Error("the renderer needs OpenGL 3.3 core; this context is " + s.version);
  }
  std::string directory = options.shader_directory;
  if (directory.empty()) {
    const char* environment = std::getenv("AUTOGRAV_SHADER_DIR");
    if (environment != nullptr) directory = environment;
  }
  const ShaderLibrary library =
      directory.empty() ? ShaderLibrary::embedded() : ShaderLibrary::fromDirectory(directory);
  s.shader_origin = library.origin();
  s.lines_program = std::make_unique<ShaderProgram>(s.gl, library, "lines.vert", "lines.frag");
  s.mesh_program = std::make_unique<ShaderProgram>(s.gl, library, "mesh.vert", "mesh.frag");
  s.overlay_program =
      std::make_unique<ShaderProgram>(s.gl, library, "overlay.vert", "overlay.frag");
  s.createLineBuffers();
  s.createMesh(s.arrow, detail::makeArrowMesh(kArrowSegments));
  s.createMesh(s.sphere, detail::makeSphereMesh(kSphereSlices, kSphereStacks));
  s.createOverlay();
  const GLenum error = s.gl.GetError();
  if (error != GL_NO_ERROR) {
    throw Error("GL error " + std::to_string(error) + " while setting up the renderer");
  }
}

Renderer::~Renderer() {
  state_->context.makeCurrent();
  state_->destroy();
}

const std::string& Renderer::glVersion() const { return state_->version; }
const std::string& Renderer::shaderOrigin() const { return state_->shader_origin; }

void Renderer::render(const Scene& scene) {
  State& s = *state_;
  GlFunctions& gl = s.gl;
  const int width = s.context.framebufferWidth();
  const int height = s.context.framebufferHeight();
  gl.Viewport(0, 0, width, height);
  gl.ClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  const double aspect = static_cast<double>(width) / std::max(height, 1);
  const Eigen::Matrix4d view_projection_d = scene.camera.projection(aspect) * scene.camera.view();
  const Eigen::Matrix4f view_projection = toFloat(view_projection_d);
  const Eigen::Vector3d eye = scene.camera.eye_m();

  detail::clearFrame(s.frame);
  const detail::FrameMeasures frame = detail::measureFrame(scene);
  detail::addSceneContent(scene, frame, s.frame);
  detail::addOverlay(scene, frame, view_projection_d, width, height, s.frame);

  gl.Enable(GL_DEPTH_TEST);
  gl.DepthMask(GL_TRUE);
  gl.Disable(GL_BLEND);
  s.drawMesh(s.arrow, s.frame.colormap_arrows, true, view_projection, eye);
  s.drawMesh(s.arrow, s.frame.plain_arrows, false, view_projection, eye);
  s.drawMesh(s.sphere, s.frame.spheres, false, view_projection, eye);
  // Translucent lines after the opaque meshes: tested against depth but not writing it.
  gl.Enable(GL_BLEND);
  gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  gl.DepthMask(GL_FALSE);
  s.drawLines(view_projection);
  gl.DepthMask(GL_TRUE);
  gl.Disable(GL_DEPTH_TEST);

  s.drawOverlay(width, height);
  gl.Disable(GL_BLEND);
}

std::vector<std::string> embeddedShaderNames() {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < detail::kEmbeddedShaderCount; ++i) {
    names.emplace_back(detail::kEmbeddedShaders[i].name);
  }
  return names;
}

}  // namespace autograv::gl
