#include "autograv/map/workspace_grid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "autograv/error.h"

namespace autograv {

double defaultGridSide_m(double workspace_radius_m) noexcept {
  return std::round(0.8 * 2.0 * workspace_radius_m / std::sqrt(3.0) * 1e3) * 1e-3;
}

WorkspaceGrid::WorkspaceGrid(const Eigen::Vector3d& center_m, double side_m, int resolution)
    : center_m_(center_m), side_m_(side_m), resolution_(resolution) {
  if (!center_m.allFinite()) throw Error("workspace grid: centre must be finite");
  if (!(std::isfinite(side_m) && side_m > 0.0)) {
    std::ostringstream message;
    message << "workspace grid: side must be a positive length in metres, got " << side_m;
    throw Error(message.str());
  }
  if (resolution < 2 || resolution > 64) {
    std::ostringstream message;
    message << "workspace grid: resolution must be 2..64 vertices per axis, got " << resolution;
    throw Error(message.str());
  }
}

Eigen::Vector3d WorkspaceGrid::minCorner_m() const noexcept {
  return center_m_ - Eigen::Vector3d::Constant(0.5 * side_m_);
}

Eigen::Vector3d WorkspaceGrid::maxCorner_m() const noexcept {
  return center_m_ + Eigen::Vector3d::Constant(0.5 * side_m_);
}

int WorkspaceGrid::vertexIndex(int ix, int iy, int iz) const noexcept {
  return ix + resolution_ * (iy + resolution_ * iz);
}

Eigen::Vector3i WorkspaceGrid::vertexCoordinates(int index) const noexcept {
  return {index % resolution_, (index / resolution_) % resolution_,
          index / (resolution_ * resolution_)};
}

Eigen::Vector3d WorkspaceGrid::vertexPosition(int index) const noexcept {
  return minCorner_m() + vertexCoordinates(index).cast<double>() * spacing_m();
}

bool WorkspaceGrid::contains(const Eigen::Vector3d& position_m, double margin_m) const noexcept {
  const Eigen::Vector3d low = minCorner_m() - Eigen::Vector3d::Constant(margin_m);
  const Eigen::Vector3d high = maxCorner_m() + Eigen::Vector3d::Constant(margin_m);
  return (position_m.array() >= low.array()).all() && (position_m.array() <= high.array()).all();
}

int WorkspaceGrid::nearestVertex(const Eigen::Vector3d& position_m) const noexcept {
  Eigen::Vector3i coordinates;
  for (int axis = 0; axis < 3; ++axis) {
    const double cell = (position_m[axis] - minCorner_m()[axis]) / spacing_m();
    const long rounded = std::lround(std::isfinite(cell) ? cell : 0.0);
    coordinates[axis] = static_cast<int>(std::clamp<long>(rounded, 0, resolution_ - 1));
  }
  return vertexIndex(coordinates.x(), coordinates.y(), coordinates.z());
}

std::vector<int> WorkspaceGrid::visitOrder(const Eigen::Vector3d& start_m) const {
  // Start at the corner nearest start_m, then sweep x, y and z in a boustrophedon so that every
  // move between consecutive vertices is a single cell edge.
  const Eigen::Vector3i start = vertexCoordinates(nearestVertex(start_m));
  const int last = resolution_ - 1;
  const bool flip_x = start.x() * 2 > last;
  const bool flip_y = start.y() * 2 > last;
  const bool flip_z = start.z() * 2 > last;
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(vertexCount()));
  for (int k = 0; k < resolution_; ++k) {
    const int iz = flip_z ? last - k : k;
    for (int j = 0; j < resolution_; ++j) {
      const int jj = (k % 2 == 0) ? j : last - j;
      const int iy = flip_y ? last - jj : jj;
      for (int i = 0; i < resolution_; ++i) {
        const int row = k * resolution_ + j;
        const int ii = (row % 2 == 0) ? i : last - i;
        const int ix = flip_x ? last - ii : ii;
        order.push_back(vertexIndex(ix, iy, iz));
      }
    }
  }
  return order;
}

}  // namespace autograv
