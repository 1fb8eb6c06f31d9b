#include "autograv/map/workspace_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "autograv/error.h"

namespace autograv {

namespace {
constexpr int kMinResolution = 2;
constexpr int kMaxResolution = 64;
constexpr const char* kAxisNames[3] = {"x", "y", "z"};
}  // namespace

double defaultGridSide_m(double workspace_radius_m) noexcept {
  return std::round(0.8 * 2.0 * workspace_radius_m / std::sqrt(3.0) * 1e3) * 1e-3;
}

WorkspaceGrid::WorkspaceGrid(const Eigen::Vector3d& center_m, double side_m, int resolution)
    : WorkspaceGrid(center_m, Eigen::Vector3d::Constant(side_m),
                    Eigen::Vector3i::Constant(resolution)) {}

WorkspaceGrid::WorkspaceGrid(const Eigen::Vector3d& center_m, const Eigen::Vector3d& size_m,
                             const Eigen::Vector3i& resolution)
    : center_m_(center_m), size_m_(size_m), resolution_(resolution) {
  if (!center_m.allFinite()) throw Error("workspace grid: centre must be finite");
  for (int axis = 0; axis < 3; ++axis) {
    if (!(std::isfinite(size_m[axis]) && size_m[axis] > 0.0)) {
      std::ostringstream message;
      message << "workspace grid: the extent along " << kAxisNames[axis]
              << " must be a positive length in metres, got " << size_m[axis];
      throw Error(message.str());
    }
    if (resolution[axis] < kMinResolution || resolution[axis] > kMaxResolution) {
      std::ostringstream message;
      message << "workspace grid: resolution must be " << kMinResolution << ".." << kMaxResolution
              << " vertices per axis, got " << resolution[axis] << " along " << kAxisNames[axis];
      throw Error(message.str());
    }
  }
}

bool WorkspaceGrid::isCube() const noexcept {
  return (resolution_.array() == resolution_.x()).all() && (size_m_.array() == size_m_.x()).all();
}

Eigen::Vector3d WorkspaceGrid::spacing_m() const noexcept {
  return size_m_.cwiseQuotient((resolution_.array() - 1).cast<double>().matrix());
}

Eigen::Vector3d WorkspaceGrid::minCorner_m() const noexcept { return center_m_ - 0.5 * size_m_; }

Eigen::Vector3d WorkspaceGrid::maxCorner_m() const noexcept { return center_m_ + 0.5 * size_m_; }

int WorkspaceGrid::vertexIndex(int ix, int iy, int iz) const noexcept {
  return ix + resolution_.x() * (iy + resolution_.y() * iz);
}

Eigen::Vector3i WorkspaceGrid::vertexCoordinates(int index) const noexcept {
  return {index % resolution_.x(), (index / resolution_.x()) % resolution_.y(),
          index / (resolution_.x() * resolution_.y())};
}

Eigen::Vector3d WorkspaceGrid::vertexPosition(int index) const noexcept {
  return minCorner_m() + vertexCoordinates(index).cast<double>().cwiseProduct(spacing_m());
}

bool WorkspaceGrid::hasVertex(const Eigen::Vector3i& coordinates) const noexcept {
  return (coordinates.array() >= 0).all() && (coordinates.array() < resolution_.array()).all();
}

bool WorkspaceGrid::contains(const Eigen::Vector3d& position_m, double margin_m) const noexcept {
  const Eigen::Vector3d low = minCorner_m() - Eigen::Vector3d::Constant(margin_m);
  const Eigen::Vector3d high = maxCorner_m() + Eigen::Vector3d::Constant(margin_m);
  return (position_m.array() >= low.array()).all() && (position_m.array() <= high.array()).all();
}

int WorkspaceGrid::nearestVertex(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d spacing = spacing_m();
  const Eigen::Vector3d low = minCorner_m();
  Eigen::Vector3i coordinates;
  for (int axis = 0; axis < 3; ++axis) {
    const double cell = (position_m[axis] - low[axis]) / spacing[axis];
    const long rounded = std::lround(std::isfinite(cell) ? cell : 0.0);
    coordinates[axis] = static_cast<int>(std::clamp<long>(rounded, 0, resolution_[axis] - 1));
  }
  return vertexIndex(coordinates.x(), coordinates.y(), coordinates.z());
}

std::vector<int> WorkspaceGrid::visitOrder(const Eigen::Vector3d& start_m) const {
  // Start at the corner nearest start_m, then sweep x, y and z in a boustrophedon so that every
  // move between consecutive vertices is a single cell edge.
  const Eigen::Vector3i start = vertexCoordinates(nearestVertex(start_m));
  const Eigen::Vector3i last = resolution_.array() - 1;
  const bool flip_x = start.x() * 2 > last.x();
  const bool flip_y = start.y() * 2 > last.y();
  const bool flip_z = start.z() * 2 > last.z();
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(vertexCount()));
  for (int k = 0; k < resolution_.z(); ++k) {
    const int iz = flip_z ? last.z() - k : k;
    for (int j = 0; j < resolution_.y(); ++j) {
      const int jj = (k % 2 == 0) ? j : last.y() - j;
      const int iy = flip_y ? last.y() - jj : jj;
      for (int i = 0; i < resolution_.x(); ++i) {
        const int row = k * resolution_.y() + j;
        const int ii = (row % 2 == 0) ? i : last.x() - i;
        const int ix = flip_x ? last.x() - ii : ii;
        order.push_back(vertexIndex(ix, iy, iz));
      }
    }
  }
  return order;
}

bool WorkspaceGrid::sameGeometry(const WorkspaceGrid& other) const noexcept {
  constexpr double kToleranceM = 1e-9;
  return resolution_ == other.resolution_ &&
         (size_m_ - other.size_m_).cwiseAbs().maxCoeff() <= kToleranceM &&
         (center_m_ - other.center_m_).cwiseAbs().maxCoeff() <= kToleranceM;
}

std::string WorkspaceGrid::describe() const {
  const Eigen::Vector3d size_mm = size_m_ * 1e3;
  const Eigen::Vector3d cell_mm = spacing_m() * 1e3;
  char text[160];
  std::snprintf(text, sizeof text,
                "%dx%dx%d vertices, %.1f x %.1f x %.1f mm (cell %.1f x %.1f x %.1f mm)",
                resolution_.x(), resolution_.y(), resolution_.z(), size_mm.x(), size_mm.y(),
                size_mm.z(), cell_mm.x(), cell_mm.y(), cell_mm.z());
  return text;
}

}  // namespace autograv
