#pragma once

#include <cstdint>
#include <functional>

#include <Eigen/Core>

#include "autograv/map/workspace_grid.h"

namespace autograv {

/// Whether the end-effector can be held at a position. Unit: [m]
using ReachabilityTest = std::function<bool(const Eigen::Vector3d& position_m)>;

/// A box for the calibration grid and how much of the reachable workspace it holds.
struct WorkspaceFit {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< Unit: [m]
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();    ///< Extents along x, y, z. Unit: [m]
  /// Fraction of the reachable workspace inside the box (workspaceCoverage, on samples other
  /// than those the box was fitted to).
  double workspace_coverage = 0.0;
};

/// Monte Carlo estimate of the fraction of the reachable workspace inside `grid`'s box: points
/// drawn uniformly in the cube of half-edge `radius_m` around `center_m` (which must hold the
/// whole reachable set), kept when `reachable`, counted when inside the box. `samples` is the
/// number of reachable points to draw; seeded, so deterministic. Its standard error is about
/// sqrt(c (1 - c) / samples). Throws autograv::Error when no reachable point turns up.
/// Not real-time safe.
double workspaceCoverage(const WorkspaceGrid& grid, const ReachabilityTest& reachable,
                         const Eigen::Vector3d& center_m, double radius_m, int samples = 20000,
                         std::uint64_t seed = 7);

/// The smallest box, found by trimming the same fraction from both ends of the reachable
/// samples' distribution along each axis, that holds at least `target_coverage` of them;
/// extents rounded up to the millimetre. The bounding region is the cube of half-edge `radius_m`
/// around `center_m`. Its coverage is then measured on fresh samples; the fit aims a little above
/// the target (three standard errors) so that the measured coverage meets it. Throws
/// autograv::Error on a target outside (0, 1] or when no reachable point turns up.
/// Not real-time safe.
WorkspaceFit fitWorkspaceBox(const ReachabilityTest& reachable, const Eigen::Vector3d& center_m,
                             double radius_m, double target_coverage = 0.9, int samples = 20000,
                             std::uint64_t seed = 3);

}  // namespace autograv
