#include "gl/meshes.h"

#include <cmath>

namespace autograv::gl::detail {

namespace {

std::uint32_t addVertex(MeshData& mesh, float x, float y, float z, float nx, float ny, float nz,
                        float a, float b) {
  mesh.vertices.push_back({{x, y, z}, {nx, ny, nz}, {a, b}});
  return static_cast<std::uint32_t>(mesh.vertices.size() - 1);
}

void addTriangle(MeshData& mesh, std::uint32_t i, std::uint32_t j, std::uint32_t k) {
  mesh.indices.insert(mesh.indices.end(), {i, j, k});
}

}  // namespace

MeshData makeArrowMesh(int segments) {
  MeshData mesh;
  const float step = 2.0f * static_cast<float>(M_PI) / static_cast<float>(segments);
  // Cone normal for the nominal head proportions: perpendicular to the slant.
  const float slant = std::hypot(kArrowHeadLength, kArrowHeadRadius);
  const float cone_radial = kArrowHeadLength / slant;
  const float cone_axial = kArrowHeadRadius / slant;
  // Axial positions as (a, b): shaft from (0, 0) to the head base (1, -1), tip at (1, 0).
  const std::uint32_t base_centre = addVertex(mesh, 0, 0, 0, 0, 0, -1, 0, 0);
  const std::uint32_t head_base_centre = addVertex(mesh, 0, 0, 0, 0, 0, -1, 1, -1);
  for (int i = 0; i < segments; ++i) {
    const float c0 = std::cos(step * static_cast<float>(i));
    const float s0 = std::sin(step * static_cast<float>(i));
    const float c1 = std::cos(step * static_cast<float>(i + 1));
    const float s1 = std::sin(step * static_cast<float>(i + 1));
    // Shaft side.
    const auto a = addVertex(mesh, c0, s0, 0, c0, s0, 0, 0, 0);
    const auto b = addVertex(mesh, c1, s1, 0, c1, s1, 0, 0, 0);
    const auto c = addVertex(mesh, c1, s1, 0, c1, s1, 0, 1, -1);
    const auto d = addVertex(mesh, c0, s0, 0, c0, s0, 0, 1, -1);
    addTriangle(mesh, a, b, c);
    addTriangle(mesh, a, c, d);
    // Shaft bottom cap, facing -w.
    const auto e = addVertex(mesh, c0, s0, 0, 0, 0, -1, 0, 0);
    const auto f = addVertex(mesh, c1, s1, 0, 0, 0, -1, 0, 0);
    addTriangle(mesh, base_centre, f, e);
    // Underside of the head, facing -w.
    const float r = kArrowHeadRadius;
    const auto g = addVertex(mesh, r * c0, r * s0, 0, 0, 0, -1, 1, -1);
    const auto h = addVertex(mesh, r * c1, r * s1, 0, 0, 0, -1, 1, -1);
    addTriangle(mesh, head_base_centre, h, g);
    // Cone; the tip gets the normal of the middle of its facet.
    const float cm = std::cos(step * (static_cast<float>(i) + 0.5f));
    const float sm = std::sin(step * (static_cast<float>(i) + 0.5f));
    const auto k =
        addVertex(mesh, r * c0, r * s0, 0, cone_radial * c0, cone_radial * s0, cone_axial, 1, -1);
    const auto l =
        addVertex(mesh, r * c1, r * s1, 0, cone_radial * c1, cone_radial * s1, cone_axial, 1, -1);
    const auto tip = addVertex(mesh, 0, 0, 0, cone_radial * cm, cone_radial * sm, cone_axial, 1, 0);
    addTriangle(mesh, k, l, tip);
  }
  return mesh;
}

MeshData makeSphereMesh(int slices, int stacks) {
  MeshData mesh;
  for (int j = 0; j <= stacks; ++j) {
    const float polar =
        static_cast<float>(M_PI) * static_cast<float>(j) / static_cast<float>(stacks);
    for (int i = 0; i <= slices; ++i) {
      const float azimuth =
          2.0f * static_cast<float>(M_PI) * static_cast<float>(i) / static_cast<float>(slices);
      const float x = std::sin(polar) * std::cos(azimuth);
      const float y = std::sin(polar) * std::sin(azimuth);
      const float z = std::cos(polar);
      addVertex(mesh, x, y, z, x, y, z, 0, 0);
    }
  }
  const auto at = [slices](int i, int j) {
    return static_cast<std::uint32_t>(j * (slices + 1) + i);
  };
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < slices; ++i) {
      // Row j is nearer +z; seen from outside, (i, j), (i, j+1), (i+1, j+1) turns anticlockwise.
      if (j != 0) addTriangle(mesh, at(i, j), at(i, j + 1), at(i + 1, j));
      if (j != stacks - 1) addTriangle(mesh, at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
    }
  }
  return mesh;
}

}  // namespace autograv::gl::detail
