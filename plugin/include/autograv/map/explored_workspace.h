#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace autograv {

/// The part of the workspace the end-effector was seen to reach, found from the device's own data
/// (WorkspaceExplorer): from a centre, how far it went along each probe direction before a stop
/// held it. The boundary is a closed surface of triangles through the boundary points, one
/// triangulation of the probe directions (their spherical Delaunay triangulation) computed once:
/// for a convex workspace the model lies inside what was reached, and it moves continuously
/// with the reach, so two explorations a fraction of a millimetre apart plan the same points.
/// Immutable once built; an empty one (maps made before exploration existed) knows nothing.
class ExploredWorkspace {
 public:
  ExploredWorkspace() = default;
  /// `directions` are normalized here; `radii_m[i]` is the distance from `center_m` to the stop
  /// along `directions[i]`. Throws autograv::Error for fewer than 6 or more than kMaxDirections
  /// directions, a count mismatch, a zero or non-finite direction, or a radius that is not finite
  /// and positive. Not real-time safe. Units: [m]
  ExploredWorkspace(const Eigen::Vector3d& center_m, std::vector<Eigen::Vector3d> directions,
                    std::vector<double> radii_m);

  /// Most probe directions a workspace holds: its triangulation takes a few seconds at this many.
  static constexpr std::size_t kMaxDirections = 10000;

  /// True when nothing was explored (every point counts as inside).
  bool empty() const noexcept { return directions_.empty(); }
  /// Where the probes started. Unit: [m]
  const Eigen::Vector3d& center_m() const noexcept { return center_m_; }
  /// The probe directions, unit vectors.
  const std::vector<Eigen::Vector3d>& directions() const noexcept { return directions_; }
  /// Distance to the stop along each direction. Unit: [m]
  const std::vector<double>& radii_m() const noexcept { return radii_m_; }

  /// Distance from the centre to the boundary along `direction` (any length). Infinite when empty.
  /// Real-time safe. Unit: [m]
  double boundaryDistance_m(const Eigen::Vector3d& direction) const noexcept;
  /// True when `position_m` lies at least `margin_m` inside the boundary (always, when empty).
  /// Real-time safe. Unit: [m]
  bool contains(const Eigen::Vector3d& position_m, double margin_m = 0.0) const noexcept;
  /// How far `position_m` lies inside the boundary (negative outside): its distance to the
  /// nearest boundary triangle, not the distance along its ray from the centre (a point a few
  /// millimetres inside along an oblique ray may be much closer to the stop). Continuous in
  /// `position_m` and in the reach. Real-time safe; its cost grows with the directions. Unit: [m]
  double depth_m(const Eigen::Vector3d& position_m) const noexcept;
  /// `position_m` itself when it lies `margin_m` inside, else the outermost point on its ray from
  /// the centre that lies `margin_m` inside the boundary (depth_m; the centre if the workspace is
  /// thinner than that). Real-time safe. Unit: [m]
  Eigen::Vector3d pullInside(const Eigen::Vector3d& position_m, double margin_m) const noexcept;
  /// How far from `position_m` the boundary lies along `direction` (a unit vector), at most
  /// `limit_m`: 0 outside, `limit_m` when empty; to `resolution_m` where no boundary triangle
  /// covers the line. Real-time safe; one pass over the triangles. Unit: [m]
  double clearanceAlong_m(const Eigen::Vector3d& position_m, const Eigen::Vector3d& direction,
                          double limit_m, double resolution_m = 5e-4) const noexcept;
  /// Smallest boundary distance. Unit: [m]
  double minRadius_m() const noexcept;
  /// Largest boundary distance. Unit: [m]
  double maxRadius_m() const noexcept;

  /// `count` directions spread evenly over the sphere (a Fibonacci lattice), ordered so that each
  /// is close to the one before: the probe's path. Not real-time safe.
  static std::vector<Eigen::Vector3d> probeDirections(int count);

  /// The boundary's triangles, as indices into directions(), counter-clockwise seen from
  /// outside. A triangulation of well-spread directions has 2 n - 4 of them.
  std::vector<std::array<int, 3>> facets() const;
  /// The boundary triangle whose cone holds the unit vector `u`: its corners (indices into
  /// directions()) and u's non-negative weights on their directions (u = sum of weight times
  /// direction). False when no triangle holds it. Real-time safe.
  bool enclosingFacet(const Eigen::Vector3d& u, std::array<int, 3>& corners,
                      Eigen::Vector3d& weights) const noexcept;

 private:
  /// One boundary triangle, with what the queries need of it precomputed.
  struct Facet {
    std::array<int, 3> corners;  ///< Indices into directions_.
    Eigen::Matrix3d to_weights;  ///< A direction to its weights on the three corner directions.
    Eigen::Vector3d normal;      ///< Outward unit normal of the triangle's plane.
    double offset_m;             ///< normal . (corner - centre). Unit: [m]
  };
  /// The facet whose cone holds the unit vector `u` (its weights on the corners in `weights`),
  /// or null.
  const Facet* facetHolding(const Eigen::Vector3d& u, Eigen::Vector3d& weights) const noexcept;
  /// Distance from the centre to where the ray along the unit vector `u` leaves the model.
  double exitDistance_m(const Eigen::Vector3d& u) const noexcept;
  /// Distance from `position_m` to the nearest boundary triangle. Unit: [m]
  double surfaceDistance_m(const Eigen::Vector3d& position_m) const noexcept;
  /// A boundary point. Unit: [m]
  Eigen::Vector3d boundaryPoint_m(int index) const noexcept;
  void buildFacets();

  Eigen::Vector3d center_m_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> directions_;
  std::vector<double> radii_m_;
  std::vector<Facet> facets_;
};

}  // namespace autograv
