#pragma once

// Private: the one trilinear interpolation on a WorkspaceGrid, shared by GravityMap::gravityAt
// (vertex estimates read in place) and the servo path's packed copy (detail::MapInterpolator).
// Written for the servo path: branch-free clamping, one weight per corner, inlined.

#include <algorithm>
#include <type_traits>

#include <Eigen/Core>

#include "autograv/workspace_grid.h"

namespace autograv::detail {

/// The few numbers of a WorkspaceGrid the interpolation needs, in the grid's own units.
struct TrilinearGrid {
  explicit TrilinearGrid(const WorkspaceGrid& grid) noexcept
      : min_corner_m(grid.minCorner_m()),
        inverse_spacing_per_m(1.0 / grid.spacing_m()),
        resolution(grid.resolution()) {}

  /// `position_m` in grid cells from the minimum corner (not clamped). Unit: [cells]
  Eigen::Vector3d toCells(const Eigen::Vector3d& position_m) const noexcept {
    return (position_m - min_corner_m) * inverse_spacing_per_m;
  }

  Eigen::Vector3d min_corner_m;
  double inverse_spacing_per_m;
  int resolution;
};

/// Trilinear interpolation at `cells` (grid coordinates from TrilinearGrid::toCells). A point
/// outside is clamped to the boundary first; a NaN coordinate counts as 0 (the minimum face).
/// `value_at(i)` returns the vertex value with index i = ix + N * (iy + N * iz).
/// Real-time safe: no allocation, no branch on the data.
template <typename ValueAt>
Eigen::Vector3d interpolateTrilinear(const TrilinearGrid& grid, const Eigen::Vector3d& cells,
                                     const ValueAt& value_at) noexcept {
  const int n = grid.resolution;
  const double last = static_cast<double>(n - 1);
  // Cell and fraction along one axis. min first, then max: std::max(0.0, NaN) is 0.0, so a NaN
  // lands on the minimum face. Written out per axis: the servo path wants no loop here.
  const auto locate = [n, last](double coordinate, double& fraction) noexcept {
    const double clamped = std::max(0.0, std::min(coordinate, last));
    const int cell = std::min(static_cast<int>(clamped), n - 2);
    fraction = clamped - cell;
    return cell;
  };
  double x1 = 0.0, y1 = 0.0, z1 = 0.0;  // fractions towards the far corner of the cell
  const int ix = locate(cells.x(), x1);
  const int iy = locate(cells.y(), y1);
  const int iz = locate(cells.z(), z1);
  const double x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
  const int base = ix + n * (iy + n * iz);
  const int dy = n;
  const int dz = n * n;
  // Vertex values may be Vector3d (read in place) or zero-padded Vector4d (two SSE packets).
  using Value = std::decay_t<decltype(value_at(0))>;
  const Value near_face = y0 * (x0 * value_at(base) + x1 * value_at(base + 1)) +
                          y1 * (x0 * value_at(base + dy) + x1 * value_at(base + dy + 1));
  const Value far_face = y0 * (x0 * value_at(base + dz) + x1 * value_at(base + dz + 1)) +
                         y1 * (x0 * value_at(base + dz + dy) + x1 * value_at(base + dz + dy + 1));
  const Value sum = z0 * near_face + z1 * far_face;
  return sum.template head<3>();
}

}  // namespace autograv::detail
