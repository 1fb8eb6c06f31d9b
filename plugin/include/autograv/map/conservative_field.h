#pragma once

#include <vector>

#include <Eigen/Core>

#include "autograv/map/workspace_grid.h"
#include "autograv/types/vertex_estimate.h"

namespace autograv {

/// The apparent gravity of a passive mechanism as what it is: the gradient of a potential. The
/// weights of the links and any balancing springs store energy U(q) in the joint angles, and the
/// force at the end-effector is J^-T dU/dq = grad_x U(x) wherever the kinematics is regular, so
/// the field has no curl whatever the device. Fitting U instead of three independent components
/// ties the components' derivatives together (dGx/dy = dGy/dx, ...), which is what lets a few
/// scattered measurements fix how the field bends between them and near the stops.
///
/// The fit is Hermite interpolation of the measured gradients with the polyharmonic kernel
/// |x|^5 (the smoothest whose system stays well conditioned at a hundred points) plus a
/// quadratic potential: it reproduces every measurement (to a relative 1e-9 ridge) and, exactly,
/// any field that is itself the gradient of a quadratic potential (G = A x + b, A symmetric: a
/// constant field, or a linear spring). No kinematic model is involved.
/// Immutable once built.
class ConservativeFieldFit {
 public:
  /// Fewest measurements a fit takes: three points in general position fix the quadratic
  /// potential's nine gradient coefficients.
  static constexpr int kMinMeasurements = 4;
  /// Most measurements a fit takes (an 8x8x8 grid's): the dense solve grows with their cube, to
  /// about a second at this many. Finer grids are dense enough for the thin-plate lookup.
  static constexpr int kMaxMeasurements = 512;

  /// Fits `values_n[i]` measured at `points_m[i]`. Throws autograv::Error for a size mismatch,
  /// fewer than kMinMeasurements or more than kMaxMeasurements points, a non-finite point or value,
  /// or points that do not determine the fit (coincident, or all on one line). Not real-time safe:
  /// a dense solve of 3 n + 9 unknowns. Units: [m], [N]
  ConservativeFieldFit(const std::vector<Eigen::Vector3d>& points_m,
                       const std::vector<Eigen::Vector3d>& values_n);

  /// The fitted field at `position_m`: a sum over every measurement, so not for the servo path
  /// (GravityMap samples it onto its lookup grid once). Units: [m], [N]
  Eigen::Vector3d at(const Eigen::Vector3d& position_m) const noexcept;

  /// The number of measurements fitted.
  int measurementCount() const noexcept { return static_cast<int>(points_.size()); }

 private:
  // Positions are fitted in scaled coordinates (centred on the points' mean, divided by their
  // largest distance from it), which keeps the kernel's fifth powers near 1.
  Eigen::Vector3d scaled(const Eigen::Vector3d& position_m) const noexcept;

  Eigen::Vector3d origin_m_ = Eigen::Vector3d::Zero();
  double scale_per_m_ = 1.0;
  std::vector<Eigen::Vector3d> points_;  ///< Scaled measurement points.
  Eigen::VectorXd kernel_weights_;       ///< Three per point. Unit: [N]
  Eigen::VectorXd polynomial_weights_;   ///< The quadratic potential's nine. Unit: [N]
};

/// How far each measurement lies from what the others predict: the conservative fit of all the
/// measurements but measurement i, evaluated at point i, minus value i (leave-one-out). Large
/// where the field bends faster than the measurements around it follow, or where a measurement
/// disagrees with its neighbours: where more measurements would help the map most. Needs no
/// ground truth. One dense factorization and inverse of the fit's 3 n + 9 unknowns (Rippa's
/// identity, per 3x3 block: residual i = -[(M^-1)_ii]^-1 c_i, with M the fit's system and c its
/// kernel weights), not n refits. Throws autograv::Error as the ConservativeFieldFit constructor
/// does, and when a measurement cannot be left out (the others no longer determine a fit).
/// Not real-time safe. Units: [m], [N]
std::vector<Eigen::Vector3d> leaveOneOutResiduals_n(const std::vector<Eigen::Vector3d>& points_m,
                                                    const std::vector<Eigen::Vector3d>& values_n);

/// How the measurements of a map agree with one another: each converged vertex's measurement
/// against the fit of all the others (leaveOneOutResiduals_n), over |G_hat| there.
struct MeasurementAgreement {
  /// A residual beyond the measurements' own error (up to about 1 % of |G_hat| next to an Omni's
  /// stops) says the field bends there faster than the measurements around it follow.
  static constexpr double kWorthMeasuring = 0.01;
  /// How many of the worst vertices least_sure_vertices lists at most.
  static constexpr int kListed = 3;
  int measurements = 0;     ///< Converged vertices.
  double median_rel = 0.0;  ///< Median of |residual| / |G_hat|.
  double p90_rel = 0.0;     ///< 90th percentile.
  double max_rel = 0.0;     ///< Largest.
  /// Vertices whose residual passes kWorthMeasuring, largest first (at most kListed): where more
  /// measurements would help the map most.
  std::vector<int> least_sure_vertices;
};

/// The agreement of the converged vertices' measurements. Throws autograv::Error as
/// leaveOneOutResiduals_n does (fewer than ConservativeFieldFit::kMinMeasurements or more than
/// kMaxMeasurements of them, or points that do not determine a fit). Not real-time safe.
MeasurementAgreement measurementAgreement(const WorkspaceGrid& grid,
                                          const std::vector<VertexEstimate>& vertices);

/// The measurements of a map: every converged vertex, at the point it was measured
/// (VertexEstimate::measuredAt_m) with the value measured there, and, when `vertex_of` is given,
/// each measurement's vertex index. Units: [m], [N]
void collectMeasurements(const WorkspaceGrid& grid, const std::vector<VertexEstimate>& vertices,
                         std::vector<Eigen::Vector3d>& points_m,
                         std::vector<Eigen::Vector3d>& values_n,
                         std::vector<int>* vertex_of = nullptr);

}  // namespace autograv
