#pragma once

#include <cstdint>
#include <vector>

namespace autograv::gl::detail {

/// Head radius of the arrow mesh, in shaft radii.
inline constexpr float kArrowHeadRadius = 2.4f;
/// Head length of an arrow long enough for it, in shaft radii (shorter arrows get a shorter head).
inline constexpr float kArrowHeadLength = 4.0f;

/// A vertex of the instanced meshes, laid out as mesh.vert expects: position = origin
/// + radius * (local.x u + local.y v) + (along[0] * length + along[1] * head + local.z * radius) w.
struct MeshVertex {
  float local[3];
  float normal[3];
  float along[2];
};

struct MeshData {
  std::vector<MeshVertex> vertices;
  std::vector<std::uint32_t> indices;  ///< Triangles, counter-clockwise seen from outside.
};

/// An arrow along +w from 0 to `length`: a closed cylinder shaft and a cone head.
MeshData makeArrowMesh(int segments);
/// A sphere of radius 1 (in units of the instance radius) centred on the origin.
MeshData makeSphereMesh(int slices, int stacks);

}  // namespace autograv::gl::detail
