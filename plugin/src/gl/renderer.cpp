#include "autograv/gl/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "autograv/error.h"
#include "autograv/map/value_kind.h"
#include "gl/embedded_shaders.h"
#include "gl/font.h"
#include "gl/gl_functions.h"
#include "gl/meshes.h"
#include "gl/shader_program.h"

namespace autograv::gl {

using detail::GlFunctions;
using detail::MeshData;
using detail::MeshVertex;
using detail::ShaderLibrary;
using detail::ShaderProgram;

namespace {

constexpr float kBackground[3] = {0.085f, 0.095f, 0.115f};
constexpr int kArrowSegments = 18;
constexpr int kSphereSlices = 24;
constexpr int kSphereStacks = 14;

/// Line vertex as lines.vert reads it.
struct LineVertex {
  float position[3];
  float color[4];
};

/// Mesh instance as mesh.vert reads it.
struct MeshInstance {
  float origin[3];
  float direction[4];  // unit direction, length [m]
  float size[2];       // radius [m], head length [m]
  float color[4];      // rgb, colour-map value
};

/// Overlay quad as overlay.vert reads it.
struct OverlayQuad {
  float rect[4];
  float color[4];
  float kind;
};

struct Rgba {
  float r, g, b, a;
};

constexpr Rgba kLatticeColor{0.52f, 0.58f, 0.68f, 0.30f};
constexpr Rgba kEdgeColor{0.70f, 0.76f, 0.86f, 0.75f};
constexpr Rgba kTrailColor{1.00f, 0.86f, 0.35f, 0.95f};
constexpr Rgba kSpringColor{0.55f, 0.95f, 0.55f, 0.90f};
constexpr Rgba kSolvedVertexColor{0.78f, 0.45f, 0.98f, 1.0f};
constexpr Rgba kOffVertexColor{1.00f, 0.55f, 0.80f, 1.0f};
constexpr Rgba kOffVertexLinkColor{1.00f, 0.55f, 0.80f, 0.70f};
constexpr Rgba kWorkspaceWireColor{0.45f, 0.65f, 1.00f, 0.40f};
constexpr Rgba kWorkspaceStopColor{0.45f, 0.65f, 1.00f, 1.0f};
constexpr Rgba kCursorFree{1.00f, 0.84f, 0.25f, 1.0f};
constexpr Rgba kCursorHeld{0.40f, 0.95f, 0.45f, 1.0f};
constexpr Rgba kForceColor{0.95f, 0.35f, 0.95f, 1.0f};
constexpr Rgba kTextColor{0.92f, 0.94f, 0.97f, 1.0f};
constexpr Rgba kPanelColor{0.0f, 0.0f, 0.0f, 0.55f};

/// A static mesh with its own per-instance buffer.
struct InstancedMesh {
  GLuint vao = 0;
  GLuint vertex_buffer = 0;
  GLuint index_buffer = 0;
  GLuint instance_buffer = 0;
  GLsizei index_count = 0;
};

void pushLine(std::vector<LineVertex>& lines, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
              Rgba ca, Rgba cb) {
  lines.push_back(
      {{static_cast<float>(a.x()), static_cast<float>(a.y()), static_cast<float>(a.z())},
       {ca.r, ca.g, ca.b, ca.a}});
  lines.push_back(
      {{static_cast<float>(b.x()), static_cast<float>(b.y()), static_cast<float>(b.z())},
       {cb.r, cb.g, cb.b, cb.a}});
}

MeshInstance makeInstance(const Eigen::Vector3d& origin, const Eigen::Vector3d& vector,
                          double radius, Rgba color, float colormap_value) {
  MeshInstance instance{};
  const double length = vector.norm();
  const Eigen::Vector3d direction =
      length > 0.0 ? Eigen::Vector3d(vector / length) : Eigen::Vector3d::UnitZ();
  const double head =
      std::min(static_cast<double>(detail::kArrowHeadLength) * radius, 0.5 * length);
  for (int i = 0; i < 3; ++i) {
    instance.origin[i] = static_cast<float>(origin[i]);
    instance.direction[i] = static_cast<float>(direction[i]);
  }
  instance.direction[3] = static_cast<float>(length);
  instance.size[0] = static_cast<float>(radius);
  instance.size[1] = static_cast<float>(head);
  instance.color[0] = color.r;
  instance.color[1] = color.g;
  instance.color[2] = color.b;
  instance.color[3] = colormap_value;
  return instance;
}

Eigen::Matrix4f toFloat(const Eigen::Matrix4d& m) { return m.cast<float>(); }

// The boundary model of an explored workspace (what the measurement plan keeps inside), drawn as
// meridians and parallels: a wire hull through the probes' stops.
void appendWorkspaceWire(const ExploredWorkspace& workspace, std::vector<LineVertex>& lines) {
  constexpr int kMeridians = 16;
  constexpr int kParallels = 7;
  constexpr int kSegments = 48;
  constexpr double kPi = 3.14159265358979323846;
  const auto boundary = [&](double polar, double azimuth) {
    const Eigen::Vector3d u(std::sin(polar) * std::cos(azimuth),
                            std::sin(polar) * std::sin(azimuth), std::cos(polar));
    return Eigen::Vector3d(workspace.center_m() + u * workspace.boundaryDistance_m(u));
  };
  for (int m = 0; m < kMeridians; ++m) {
    const double azimuth = 2.0 * kPi * m / kMeridians;
    Eigen::Vector3d previous = boundary(0.0, azimuth);
    for (int k = 1; k <= kSegments / 2; ++k) {
      const Eigen::Vector3d next = boundary(kPi * k / (kSegments / 2), azimuth);
      pushLine(lines, previous, next, kWorkspaceWireColor, kWorkspaceWireColor);
      previous = next;
    }
  }
  for (int p = 1; p <= kParallels; ++p) {
    const double polar = kPi * p / (kParallels + 1);
    Eigen::Vector3d previous = boundary(polar, 0.0);
    for (int k = 1; k <= kSegments; ++k) {
      const Eigen::Vector3d next = boundary(polar, 2.0 * kPi * k / kSegments);
      pushLine(lines, previous, next, kWorkspaceWireColor, kWorkspaceWireColor);
      previous = next;
    }
  }
}

std::string formatNewtons(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f N", value);
  return text;
}

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

  GLuint line_vao = 0;
  GLuint line_buffer = 0;
  InstancedMesh arrow;
  InstancedMesh sphere;
  GLuint overlay_vao = 0;
  GLuint overlay_corner_buffer = 0;
  GLuint overlay_instance_buffer = 0;
  GLuint font_texture = 0;
  int font_columns = detail::kAtlasColumns;

  // Staging vectors kept between frames so a steady scene does not reallocate.
  std::vector<LineVertex> line_vertices;
  std::vector<MeshInstance> arrow_instances;
  std::vector<MeshInstance> colormap_arrow_instances;
  std::vector<MeshInstance> sphere_instances;
  std::vector<OverlayQuad> overlay_quads;
  // The workspace wire of `wire_map`, made once per map: the boundary model costs a search per
  // point, too much to redo every frame.
  std::shared_ptr<const GravityMap> wire_map;
  std::vector<LineVertex> wire_lines;

  void createLineBuffers();
  void createMesh(InstancedMesh& mesh, const MeshData& data);
  void createOverlay();
  void destroy();

  void drawLines(const Eigen::Matrix4f& view_projection);
  void drawMesh(InstancedMesh& mesh, const std::vector<MeshInstance>& instances, bool colormap,
                const Eigen::Matrix4f& view_projection, const Eigen::Vector3d& eye);
  void drawOverlay(int width, int height);

  void addText(double x, double y, int scale, const std::string& text, Rgba color);
  void addRect(double x, double y, double w, double h, Rgba color, float kind = -1.0f);
};

void Renderer::State::createLineBuffers() {
  gl.GenVertexArrays(1, &line_vao);
  gl.GenBuffers(1, &line_buffer);
  gl.BindVertexArray(line_vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, line_buffer);
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
  gl.GenVertexArrays(1, &overlay_vao);
  gl.GenBuffers(1, &overlay_corner_buffer);
  gl.GenBuffers(1, &overlay_instance_buffer);
  gl.BindVertexArray(overlay_vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay_corner_buffer);
  gl.BufferData(GL_ARRAY_BUFFER, sizeof(corners), corners, GL_STATIC_DRAW);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay_instance_buffer);
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
  gl.GenTextures(1, &font_texture);
  gl.BindTexture(GL_TEXTURE_2D, font_texture);
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
  for (InstancedMesh* mesh : {&arrow, &sphere}) {
    if (mesh->vao != 0) gl.DeleteVertexArrays(1, &mesh->vao);
    const GLuint buffers[] = {mesh->vertex_buffer, mesh->index_buffer, mesh->instance_buffer};
    gl.DeleteBuffers(3, buffers);
  }
  if (line_vao != 0) gl.DeleteVertexArrays(1, &line_vao);
  if (overlay_vao != 0) gl.DeleteVertexArrays(1, &overlay_vao);
  const GLuint buffers[] = {line_buffer, overlay_corner_buffer, overlay_instance_buffer};
  gl.DeleteBuffers(3, buffers);
  if (font_texture != 0) gl.DeleteTextures(1, &font_texture);
}

void Renderer::State::addRect(double x, double y, double w, double h, Rgba color, float kind) {
  overlay_quads.push_back(
      {{static_cast<float>(x), static_cast<float>(y), static_cast<float>(w), static_cast<float>(h)},
       {color.r, color.g, color.b, color.a},
       kind});
}

void Renderer::State::addText(double x, double y, int scale, const std::string& text, Rgba color) {
  const double advance = detail::kCellWidth * scale;
  double pen = x;
  for (const char c : text) {
    if (c != ' ') {
      addRect(pen, y, detail::kCellWidth * scale, detail::kCellHeight * scale, color,
              static_cast<float>(detail::glyphIndex(c)));
    }
    pen += advance;
  }
}

void Renderer::State::drawLines(const Eigen::Matrix4f& view_projection) {
  if (line_vertices.empty()) return;
  lines_program->use();
  gl.UniformMatrix4fv(lines_program->uniform("u_view_projection"), 1, GL_FALSE,
                      view_projection.data());
  gl.BindVertexArray(line_vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, line_buffer);
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
  if (overlay_quads.empty()) return;
  overlay_program->use();
  gl.Uniform2f(overlay_program->uniform("u_viewport_px"), static_cast<float>(width),
               static_cast<float>(height));
  gl.Uniform1i(overlay_program->uniform("u_font"), 0);
  gl.Uniform1i(overlay_program->uniform("u_font_columns"), font_columns);
  gl.Uniform2i(overlay_program->uniform("u_cell_texels"), detail::kCellWidth, detail::kCellHeight);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D, font_texture);
  gl.BindVertexArray(overlay_vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay_instance_buffer);
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

  s.line_vertices.clear();
  s.colormap_arrow_instances.clear();
  s.arrow_instances.clear();
  s.sphere_instances.clear();
  s.overlay_quads.clear();

  // Sizes follow the grid when there is one, else the camera distance.
  double cell_m = 0.1 * scene.camera.distance_m;
  double min_magnitude = 0.0;
  double max_magnitude = 0.0;
  double scale_m_per_n = scene.arrow_scale_m_per_n;
  int at_vertex_count = 0;
  int solved_count = 0;
  int off_vertex_count = 0;
  int workspace_stops = 0;
  const GravityMap* map = scene.map.get();
  const WorkspaceGrid* lattice = map != nullptr ? &map->grid()
                                 : scene.grid   ? &*scene.grid
                                                : nullptr;
  if (lattice != nullptr) cell_m = lattice->spacing_m().minCoeff();
  if (map != nullptr) {
    const WorkspaceGrid& grid = map->grid();
    min_magnitude = std::numeric_limits<double>::infinity();
    for (const VertexEstimate& vertex : map->vertices()) {
      const double magnitude = vertex.gravity_n.norm();
      min_magnitude = std::min(min_magnitude, magnitude);
      max_magnitude = std::max(max_magnitude, magnitude);
    }
    if (scale_m_per_n <= 0.0)
      scale_m_per_n = max_magnitude > 0.0 ? 0.8 * cell_m / max_magnitude : 0.0;
    const double span = max_magnitude - min_magnitude;
    if (scene.show_arrows) {
      const double radius = 0.035 * cell_m;
      for (int i = 0; i < grid.vertexCount(); ++i) {
        const Eigen::Vector3d& g = map->vertices()[static_cast<std::size_t>(i)].gravity_n;
        const double value = span > 1e-12 ? (g.norm() - min_magnitude) / span : 0.5;
        s.colormap_arrow_instances.push_back(makeInstance(grid.vertexPosition(i), g * scale_m_per_n,
                                                          radius, Rgba{0, 0, 0, 1},
                                                          static_cast<float>(value)));
      }
    }
    // Vertices out of reach, solved from the measurements: a purple bead, so that a solved value
    // is never mistaken for a measured one.
    for (int i = 0; i < grid.vertexCount(); ++i) {
      const VertexEstimate& vertex = map->vertices()[static_cast<std::size_t>(i)];
      const ValueKind kind = valueKind(vertex);
      if (kind == ValueKind::kAtVertex) ++at_vertex_count;
      if (kind == ValueKind::kSolved) {
        s.sphere_instances.push_back(makeInstance(grid.vertexPosition(i), Eigen::Vector3d::Zero(),
                                                  0.06 * cell_m, kSolvedVertexColor, 0.0f));
        ++solved_count;
      }
    }
    // Points measured inside the stops for vertices beyond them: a pink bead with the measured
    // arrow (thinner than the vertex arrows) and a line to the vertex.
    for (int i = 0; i < grid.vertexCount(); ++i) {
      const VertexEstimate& vertex = map->vertices()[static_cast<std::size_t>(i)];
      if (valueKind(vertex) != ValueKind::kOffVertex) continue;
      ++off_vertex_count;
      if (!scene.show_measurements) continue;
      s.sphere_instances.push_back(makeInstance(vertex.measured_at_m, Eigen::Vector3d::Zero(),
                                                0.05 * cell_m, kOffVertexColor, 0.0f));
      pushLine(s.line_vertices, vertex.measured_at_m, grid.vertexPosition(i), kOffVertexLinkColor,
               kOffVertexLinkColor);
      if (scene.show_arrows) {
        const Eigen::Vector3d& g = vertex.measured_gravity_n;
        const double value =
            span > 1e-12 ? std::clamp((g.norm() - min_magnitude) / span, 0.0, 1.0) : 0.5;
        s.colormap_arrow_instances.push_back(makeInstance(vertex.measured_at_m, g * scale_m_per_n,
                                                          0.025 * cell_m, Rgba{0, 0, 0, 1},
                                                          static_cast<float>(value)));
      }
    }
    const ExploredWorkspace& workspace = map->metadata().workspace;
    workspace_stops = static_cast<int>(workspace.directions().size());
    if (scene.show_workspace && !workspace.empty()) {
      if (s.wire_map != scene.map) {
        s.wire_lines.clear();
        appendWorkspaceWire(workspace, s.wire_lines);
        s.wire_map = scene.map;
      }
      s.line_vertices.insert(s.line_vertices.end(), s.wire_lines.begin(), s.wire_lines.end());
      for (std::size_t i = 0; i < workspace.directions().size(); ++i) {
        const Eigen::Vector3d stop =
            workspace.center_m() + workspace.directions()[i] * workspace.radii_m()[i];
        s.sphere_instances.push_back(
            makeInstance(stop, Eigen::Vector3d::Zero(), 0.035 * cell_m, kWorkspaceStopColor, 0.0f));
      }
    }
  }
  if (lattice != nullptr && scene.show_grid) {
    const WorkspaceGrid& grid = *lattice;
    const Eigen::Vector3i& n = grid.resolution();
    const Eigen::Vector3d spacing_m = grid.spacing_m();
    const Eigen::Vector3d lo = grid.minCorner_m();
    const Eigen::Vector3d hi = grid.maxCorner_m();
    for (int axis = 0; axis < 3; ++axis) {
      const int a1 = (axis + 1) % 3;
      const int a2 = (axis + 2) % 3;
      for (int j = 0; j < n[a1]; ++j) {
        for (int k = 0; k < n[a2]; ++k) {
          Eigen::Vector3d from = lo;
          from[a1] += j * spacing_m[a1];
          from[a2] += k * spacing_m[a2];
          Eigen::Vector3d to = from;
          to[axis] = hi[axis];
          const bool edge = (j == 0 || j == n[a1] - 1) && (k == 0 || k == n[a2] - 1);
          const Rgba color = edge ? kEdgeColor : kLatticeColor;
          pushLine(s.line_vertices, from, to, color, color);
        }
      }
    }
    // Axis triad at the minimum corner: x red, y green, z blue.
    const double length = 0.6 * cell_m;
    pushLine(s.line_vertices, lo, lo + length * Eigen::Vector3d::UnitX(), {1.0f, 0.3f, 0.3f, 1},
             {1.0f, 0.3f, 0.3f, 1});
    pushLine(s.line_vertices, lo, lo + length * Eigen::Vector3d::UnitY(), {0.3f, 1.0f, 0.3f, 1},
             {0.3f, 1.0f, 0.3f, 1});
    pushLine(s.line_vertices, lo, lo + length * Eigen::Vector3d::UnitZ(), {0.4f, 0.5f, 1.0f, 1},
             {0.4f, 0.5f, 1.0f, 1});
  }
  if (scale_m_per_n <= 0.0) scale_m_per_n = 0.8 * cell_m;  // 0.8 cell per newton without a map

  // Trail: older segments fade out.
  const std::size_t trail_size = scene.trail_m.size();
  for (std::size_t i = 1; i < trail_size; ++i) {
    Rgba older = kTrailColor;
    Rgba newer = kTrailColor;
    older.a *= static_cast<float>(i - 1) / static_cast<float>(trail_size - 1);
    newer.a *= static_cast<float>(i) / static_cast<float>(trail_size - 1);
    pushLine(s.line_vertices, scene.trail_m[i - 1], scene.trail_m[i], older, newer);
  }
  if (scene.show_hand_target) {
    s.sphere_instances.push_back(makeInstance(scene.hand_target_m, Eigen::Vector3d::Zero(),
                                              0.07 * cell_m, kSpringColor, 0.0f));
    if (scene.show_cursor) {
      pushLine(s.line_vertices, scene.hand_target_m, scene.cursor_m, kSpringColor, kSpringColor);
    }
  }
  if (scene.show_cursor) {
    s.sphere_instances.push_back(makeInstance(scene.cursor_m, Eigen::Vector3d::Zero(),
                                              0.22 * cell_m,
                                              scene.cursor_held ? kCursorHeld : kCursorFree, 0.0f));
    if (scene.show_force && scene.force_n.norm() > 1e-9) {
      s.arrow_instances.push_back(makeInstance(scene.cursor_m, scene.force_n * scale_m_per_n,
                                               0.05 * cell_m, kForceColor, 0.0f));
    }
  }

  gl.Enable(GL_DEPTH_TEST);
  gl.DepthMask(GL_TRUE);
  gl.Disable(GL_BLEND);
  s.drawMesh(s.arrow, s.colormap_arrow_instances, true, view_projection, eye);
  s.drawMesh(s.arrow, s.arrow_instances, false, view_projection, eye);
  s.drawMesh(s.sphere, s.sphere_instances, false, view_projection, eye);
  // Translucent lines after the opaque meshes: tested against depth but not writing it.
  gl.Enable(GL_BLEND);
  gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  gl.DepthMask(GL_FALSE);
  s.drawLines(view_projection);
  gl.DepthMask(GL_TRUE);
  gl.Disable(GL_DEPTH_TEST);

  // Overlay: readout panel top-left, legend under it, status line at the bottom.
  const int scale = height >= 700 ? 3 : (height >= 360 ? 2 : 1);
  const double line_px = (detail::kCellHeight + 3) * scale;
  const double margin = 4.0 * scale;
  double panel_height = 0.0;
  std::size_t longest = 0;
  for (const std::string& line : scene.readout) longest = std::max(longest, line.size());
  const bool legend = scene.show_legend && map != nullptr && scene.show_arrows;
  const std::string legend_low = "|G| " + formatNewtons(min_magnitude);
  const std::string legend_high = formatNewtons(max_magnitude);
  if (legend) longest = std::max<std::size_t>(longest, legend_low.size() + legend_high.size() + 12);
  // The key of the kinds of value, in the colours of their marks; only the kinds present.
  struct KeyLine {
    std::string text;
    Rgba color;
  };
  std::vector<KeyLine> key;
  if (legend) {
    if (off_vertex_count > 0 || solved_count > 0) {
      key.push_back({"MEASURED AT THE VERTEX " + std::to_string(at_vertex_count), kTextColor});
    }
    if (off_vertex_count > 0 && scene.show_measurements) {
      key.push_back(
          {"MEASURED INSIDE THE STOPS " + std::to_string(off_vertex_count), kOffVertexColor});
    }
    if (solved_count > 0) {
      key.push_back(
          {"SOLVED FROM THE MEASUREMENTS " + std::to_string(solved_count), kSolvedVertexColor});
    }
    if (workspace_stops > 0 && scene.show_workspace) {
      key.push_back({"EXPLORED WORKSPACE " + std::to_string(workspace_stops) + " STOPS",
                     kWorkspaceStopColor});
    }
    for (const KeyLine& line : key) longest = std::max(longest, line.text.size());
  }
  if (!scene.readout.empty() || legend) {
    panel_height = line_px * static_cast<double>(scene.readout.size()) + 2 * margin;
    if (legend) panel_height += line_px * (2.0 + static_cast<double>(key.size()));
    s.addRect(0, 0, static_cast<double>(longest) * detail::kCellWidth * scale + 2 * margin,
              panel_height, kPanelColor);
  }
  double y = margin;
  for (const std::string& line : scene.readout) {
    s.addText(margin, y, scale, line, kTextColor);
    y += line_px;
  }
  if (legend) {
    y += 0.5 * line_px;
    const double text_w = static_cast<double>(legend_low.size()) * detail::kCellWidth * scale;
    const double bar_w = 10.0 * detail::kCellWidth * scale;
    s.addText(margin, y, scale, legend_low, kTextColor);
    s.addRect(margin + text_w + detail::kCellWidth * scale, y, bar_w, detail::kGlyphHeight * scale,
              {1, 1, 1, 1}, -2.0f);
    s.addText(margin + text_w + bar_w + 2.0 * detail::kCellWidth * scale, y, scale, legend_high,
              kTextColor);
    for (const KeyLine& line : key) {
      y += line_px;
      s.addText(margin, y, scale, line.text, line.color);
    }
  }
  if (!scene.status_line.empty()) {
    const double bar_h = line_px + 2 * margin;
    s.addRect(0, height - bar_h, width, bar_h, kPanelColor);
    s.addText(margin, height - bar_h + margin + 0.15 * line_px, scale, scene.status_line,
              kTextColor);
  }
  // Axis letters next to the triad, projected to the screen.
  if (lattice != nullptr && scene.show_grid) {
    const Eigen::Vector3d lo = lattice->minCorner_m();
    const char* names[] = {"X", "Y", "Z"};
    const Rgba colors[] = {
        {1.0f, 0.45f, 0.45f, 1}, {0.45f, 1.0f, 0.45f, 1}, {0.55f, 0.65f, 1.0f, 1}};
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d tip = lo + 0.75 * cell_m * Eigen::Vector3d::Unit(axis);
      const Eigen::Vector4d clip = view_projection_d * tip.homogeneous();
      if (clip.w() <= 0.0) continue;
      const double px = (clip.x() / clip.w() * 0.5 + 0.5) * width;
      const double py = (0.5 - clip.y() / clip.w() * 0.5) * height;
      s.addText(px - 0.5 * detail::kCellWidth * scale, py - 0.5 * detail::kCellHeight * scale,
                scale, names[axis], colors[axis]);
    }
  }
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
