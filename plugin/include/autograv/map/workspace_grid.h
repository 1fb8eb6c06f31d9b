#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace autograv {

/// Default grid edge for a workspace sphere of `workspace_radius_m`: 80 % of the inscribed cube
/// (clear of the end stops), rounded to the millimetre. Unit: [m]. Real-time safe.
double defaultGridSide_m(double workspace_radius_m) noexcept;

/// A box-shaped grid of nx * ny * nz vertices centred on `center_m` (paper Section I; the paper's
/// authors calibrate a parallelepiped). A cube is the special case of equal extents and
/// resolutions. Vertex index = ix + nx * (iy + ny * iz), with ix along +x.
class WorkspaceGrid {
 public:
  /// A cube: `side_m` is the edge of the whole cube. Unit: [m]. `resolution` >= 2 vertices per
  /// axis. Throws autograv::Error on a non-finite centre, a non-positive side or a resolution
  /// outside 2..64.
  WorkspaceGrid(const Eigen::Vector3d& center_m, double side_m, int resolution);
  /// A box: `size_m` is the extent along x, y and z of the whole box. Unit: [m]. `resolution` is
  /// the number of vertices along each axis (2..64). Throws autograv::Error as above, naming the
  /// axis.
  WorkspaceGrid(const Eigen::Vector3d& center_m, const Eigen::Vector3d& size_m,
                const Eigen::Vector3i& resolution);

  /// Centre of the box. Unit: [m]
  const Eigen::Vector3d& center_m() const noexcept { return center_m_; }
  /// Extent of the whole box along x, y and z. Unit: [m]
  const Eigen::Vector3d& size_m() const noexcept { return size_m_; }
  /// Vertices along x, y and z.
  const Eigen::Vector3i& resolution() const noexcept { return resolution_; }
  /// Vertices in all, the product of the resolution.
  int vertexCount() const noexcept { return resolution_.prod(); }
  /// True when the three extents and the three resolutions are equal.
  bool isCube() const noexcept;
  /// Edges of one grid cell along x, y and z. Unit: [m]
  Eigen::Vector3d spacing_m() const noexcept;
  /// Longest cell edge: the longest move between neighbouring vertices. Unit: [m]
  double maxSpacing_m() const noexcept { return spacing_m().maxCoeff(); }
  /// Corner of the box with the smallest coordinates. Unit: [m]
  Eigen::Vector3d minCorner_m() const noexcept;
  /// Corner of the box with the largest coordinates. Unit: [m]
  Eigen::Vector3d maxCorner_m() const noexcept;

  /// Real-time safe.
  int vertexIndex(int ix, int iy, int iz) const noexcept;
  /// Real-time safe.
  Eigen::Vector3i vertexCoordinates(int index) const noexcept;
  /// Real-time safe. Unit: [m]
  Eigen::Vector3d vertexPosition(int index) const noexcept;
  /// Real-time safe. True when the vertex coordinates lie inside the grid.
  bool hasVertex(const Eigen::Vector3i& coordinates) const noexcept;
  /// Real-time safe. True when `position_m` lies in the box grown by `margin_m` on every side.
  bool contains(const Eigen::Vector3d& position_m, double margin_m = 0.0) const noexcept;
  /// Real-time safe. The vertex closest to `position_m`.
  int nearestVertex(const Eigen::Vector3d& position_m) const noexcept;

  /// Every vertex once, in a serpentine order (each move is one cell edge), starting at the corner
  /// nearest `start_m`. Not real-time safe (allocates).
  std::vector<int> visitOrder(const Eigen::Vector3d& start_m) const;

  /// Same centre, extents and resolutions (within 1 nm). Real-time safe.
  bool sameGeometry(const WorkspaceGrid& other) const noexcept;
  /// "7x5x4 vertices, 160.0 x 120.0 x 70.0 mm (cell 26.7 x 30.0 x 23.3 mm)" for people.
  /// Not real-time safe.
  std::string describe() const;

 private:
  Eigen::Vector3d center_m_;
  Eigen::Vector3d size_m_;
  Eigen::Vector3i resolution_;
};

}  // namespace autograv
