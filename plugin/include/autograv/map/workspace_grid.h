#pragma once

#include <vector>

#include <Eigen/Core>

namespace autograv {

/// Default grid edge for a workspace sphere of `workspace_radius_m`: 80 % of the inscribed cube
/// (clear of the end stops), rounded to the millimetre. Unit: [m]. Real-time safe.
double defaultGridSide_m(double workspace_radius_m) noexcept;

/// A cubic grid of resolution^3 vertices centred in the workspace (paper Section I).
/// Vertex index = ix + N * (iy + N * iz), with N = resolution and ix along +x.
class WorkspaceGrid {
 public:
  /// `side_m` is the edge of the whole cube. Unit: [m]. `resolution` >= 2 vertices per axis.
  /// Throws autograv::Error on a non-finite centre, a non-positive side or resolution < 2.
  WorkspaceGrid(const Eigen::Vector3d& center_m, double side_m, int resolution);

  const Eigen::Vector3d& center_m() const noexcept { return center_m_; }
  double side_m() const noexcept { return side_m_; }
  int resolution() const noexcept { return resolution_; }
  int vertexCount() const noexcept { return resolution_ * resolution_ * resolution_; }
  /// Edge of one grid cell. Unit: [m]
  double spacing_m() const noexcept { return side_m_ / (resolution_ - 1); }
  Eigen::Vector3d minCorner_m() const noexcept;
  Eigen::Vector3d maxCorner_m() const noexcept;

  /// Real-time safe.
  int vertexIndex(int ix, int iy, int iz) const noexcept;
  /// Real-time safe.
  Eigen::Vector3i vertexCoordinates(int index) const noexcept;
  /// Real-time safe. Unit: [m]
  Eigen::Vector3d vertexPosition(int index) const noexcept;
  /// Real-time safe. True when `position_m` lies in the cube grown by `margin_m` on every side.
  bool contains(const Eigen::Vector3d& position_m, double margin_m = 0.0) const noexcept;
  /// Real-time safe. The vertex closest to `position_m`.
  int nearestVertex(const Eigen::Vector3d& position_m) const noexcept;

  /// Every vertex once, in a serpentine order (each move is one cell edge), starting at the corner
  /// nearest `start_m`. Not real-time safe (allocates).
  std::vector<int> visitOrder(const Eigen::Vector3d& start_m) const;

 private:
  Eigen::Vector3d center_m_;
  double side_m_;
  int resolution_;
};

}  // namespace autograv
