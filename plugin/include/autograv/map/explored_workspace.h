#pragma once

#include <vector>

#include <Eigen/Core>

namespace autograv {

/// The part of the workspace the end-effector was seen to reach, found from the device's own data
/// (WorkspaceExplorer): from a centre, how far it went along each probe direction before a stop
/// held it. Between the probe directions the boundary is the plane through the three nearest
/// boundary points, so for a convex workspace the model lies inside what was reached.
/// Immutable once built; an empty one (maps made before exploration existed) knows nothing.
class ExploredWorkspace {
 public:
  ExploredWorkspace() = default;
  /// `directions` are normalized here; `radii_m[i]` is the distance from `center_m` to the stop
  /// along `directions[i]`. Throws autograv::Error for fewer than 6 directions, a count mismatch,
  /// a zero or non-finite direction, or a radius that is not finite and positive.
  /// Not real-time safe. Units: [m]
  ExploredWorkspace(const Eigen::Vector3d& center_m, std::vector<Eigen::Vector3d> directions,
                    std::vector<double> radii_m);

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
  /// How far `position_m` lies inside the boundary (negative outside), measured square to the
  /// boundary facet its ray from the centre meets: a point a few millimetres inside along an
  /// oblique ray may be much closer to the stop. Real-time safe. Unit: [m]
  double depth_m(const Eigen::Vector3d& position_m) const noexcept;
  /// `position_m` itself when it lies `margin_m` inside, else the point on its ray from the
  /// centre that lies `margin_m` inside the boundary (depth_m; the centre if the workspace is
  /// thinner than that). Real-time safe. Unit: [m]
  Eigen::Vector3d pullInside(const Eigen::Vector3d& position_m, double margin_m) const noexcept;
  /// Smallest boundary distance. Unit: [m]
  double minRadius_m() const noexcept;
  /// Largest boundary distance. Unit: [m]
  double maxRadius_m() const noexcept;

  /// `count` directions spread evenly over the sphere (a Fibonacci lattice), ordered so that each
  /// is close to the one before: the probe's path. Not real-time safe.
  static std::vector<Eigen::Vector3d> probeDirections(int count);

 private:
  /// Where the ray from the centre along the unit vector `u` leaves the model, and the cosine
  /// between `u` and the outward normal of the facet it leaves through (at least
  /// kMinFacetCosine, 1 where no facet holds `u`).
  struct Exit {
    double distance_m;
    double cosine;
  };
  Exit exitAlong(const Eigen::Vector3d& u) const noexcept;
  /// Floor on Exit::cosine: a facet seen this obliquely is treated as seen at this angle.
  static constexpr double kMinFacetCosine = 0.25;

  Eigen::Vector3d center_m_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> directions_;
  std::vector<double> radii_m_;
};

}  // namespace autograv
