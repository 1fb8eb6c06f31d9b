#pragma once

// Private: the trilinear interpolation behind GravityMap::gravityAt, written for the servo path:
// vertex values packed as aligned Vector4d (two SSE packets each), the eight corners addressed
// from one base pointer, no loop.

#include <algorithm>
#include <cstddef>

#include <Eigen/Core>

namespace autograv::detail {

/// Trilinear interpolation at `cells`, a position in grid cells from the minimum corner of a grid
/// of `n` = (nx, ny, nz) vertices along the axes. A point outside is clamped to the boundary
/// first; a NaN coordinate counts as 0 (the minimum face).
/// `values[i]` is the vertex value with index i = ix + nx * (iy + ny * iz), the fourth component
/// zero. Real-time safe.
inline Eigen::Vector3d interpolateTrilinear(const Eigen::Vector3i& n, const Eigen::Vector3d& cells,
                                            const Eigen::Vector4d* values) noexcept {
  // Cell and fraction along one axis of `count` vertices. min first, then max:
  // std::max(0.0, NaN) is 0.0, so a NaN lands on the minimum face.
  const auto locate = [](double coordinate, int count, double& fraction) noexcept {
    const double clamped = std::max(0.0, std::min(coordinate, static_cast<double>(count - 1)));
    const int cell = std::min(static_cast<int>(clamped), count - 2);
    fraction = clamped - cell;
    return cell;
  };
  double x1 = 0.0, y1 = 0.0, z1 = 0.0;  // fractions towards the far corner of the cell
  const int ix = locate(cells.x(), n.x(), x1);
  const int iy = locate(cells.y(), n.y(), y1);
  const int iz = locate(cells.z(), n.z(), z1);
  const double x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
  const Eigen::Vector4d* v = values + (ix + n.x() * (iy + n.y() * iz));
  const std::ptrdiff_t dy = n.x();
  const std::ptrdiff_t dz = static_cast<std::ptrdiff_t>(n.x()) * n.y();
  const Eigen::Vector4d near_face =
      y0 * (x0 * v[0] + x1 * v[1]) + y1 * (x0 * v[dy] + x1 * v[dy + 1]);
  const Eigen::Vector4d far_face =
      y0 * (x0 * v[dz] + x1 * v[dz + 1]) + y1 * (x0 * v[dz + dy] + x1 * v[dz + dy + 1]);
  const Eigen::Vector4d sum = z0 * near_face + z1 * far_face;
  return sum.head<3>();
}

}  // namespace autograv::detail
