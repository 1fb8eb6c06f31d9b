#pragma once

#include <Eigen/Core>

namespace autograv::sim {

/// The paper (Formaglio, Mulatto, Prattichizzo, Section V) gives positions in millimetres in the
/// Omega SDK's frame: x to the right, y up, z toward the user. CHAI3D's frame, used everywhere in
/// autograv, has x toward the user, y to the right, z up, in metres. The two are a proper rotation
/// (a cyclic permutation of the axes) plus the unit change:
///   chai3d = 0.001 * [paper_z, paper_x, paper_y]
/// e.g. the paper's X_D = [0, -30, 0] mm is [0, 0, -0.030] m here, and its start
/// [-9.2, -68.3, 11.6] mm is [0.0116, -0.0092, -0.0683] m. Real-time safe. Units: [mm] -> [m]
inline Eigen::Vector3d paperToChai3dFrame(const Eigen::Vector3d& paper_mm) noexcept {
  return 0.001 * Eigen::Vector3d(paper_mm.z(), paper_mm.x(), paper_mm.y());
}

/// Inverse of paperToChai3dFrame. Real-time safe. Units: [m] -> [mm]
inline Eigen::Vector3d chai3dToPaperFrame(const Eigen::Vector3d& chai3d_m) noexcept {
  return 1000.0 * Eigen::Vector3d(chai3d_m.y(), chai3d_m.z(), chai3d_m.x());
}

/// The paper's estimation target X_D = [0, -30, 0] mm, in CHAI3D's frame. Unit: [m]
inline Eigen::Vector3d paperTargetPoint_m() noexcept {
  return paperToChai3dFrame(Eigen::Vector3d(0.0, -30.0, 0.0));
}

/// The paper's (random) start position [-9.2, -68.3, 11.6] mm, in CHAI3D's frame. Unit: [m]
inline Eigen::Vector3d paperStartPoint_m() noexcept {
  return paperToChai3dFrame(Eigen::Vector3d(-9.2, -68.3, 11.6));
}

/// Apparent mass the paper measured at X_D with a force sensor (Fig. 9). Unit: [kg]
inline constexpr double kPaperMeasuredMass_kg = 0.214;

}  // namespace autograv::sim
