#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

/// \file
/// What the inner loop leaves at one vertex (the estimation writes it, GravityMap keeps it):
/// below both the estimation and the map, so that neither includes the other's folder.

namespace autograv {

/// One inner-loop iteration j at a vertex: what the paper plots in Figs. 8 and 9.
struct IterationRecord {
  /// ||Delta_j|| = ||X_i - X_inf||, steady-state positioning error. Unit: [m]
  double position_error_m = 0.0;
  /// M_hat_j = ||G_hat_j|| / g. Unit: [kg]
  double mass_estimate_kg = 0.0;
  /// G_hat_{j+1}, the estimate produced at the end of this iteration (eq. 12). Unit: [N]
  Eigen::Vector3d gravity_estimate_n = Eigen::Vector3d::Zero();
  /// Time from the start of the iteration to its steady state. Unit: [s]
  double duration_s = 0.0;
};

/// Why a vertex ended the way it did.
enum class VertexOutcome : std::uint8_t {
  kPending,        ///< Not visited yet.
  kConverged,      ///< n_G consecutive updates within eps_G.
  kIterationCap,   ///< max_iterations reached first; the last estimate is kept.
  kNoSteadyState,  ///< An iteration never settled (maps written before kUnreachable existed).
  kSaturated,      ///< The actuators saturated while holding the vertex (maps written before
                   ///< kUnreachable existed; the estimator now reports kUnreachable).
  kDeviceFault,    ///< The device stopped answering or sent non-finite samples.
  kUnreachable,    ///< The device could not be held at the vertex (end stop, saturation,
                   ///< singular pose); its value is filled from measured neighbours.
  kLeftOut,        ///< Converged, but the other measurements contradicted it twice, the second
                   ///< time measured again further from the stops (judgeMeasurements): what it
                   ///< measured stays in measured_at_m / measured_gravity_n, and its value is
                   ///< filled from the others as an unreachable vertex's is (maps of schema 7).
};

/// Where a vertex's value comes from.
enum class VertexProvenance : std::uint8_t {
  kMeasured,  ///< Estimated at the vertex itself (or not yet: see the outcome).
  kFilled,    ///< Interpolated or extrapolated from measured vertices (fillUnmeasuredVertices).
};

/// Stable lower-case name used in files and reports ("converged", "iteration_cap", ...).
const char* toString(VertexOutcome outcome) noexcept;
/// Inverse of toString; returns false for an unknown name.
bool parseVertexOutcome(const std::string& name, VertexOutcome& outcome) noexcept;
/// "measured" or "filled".
const char* toString(VertexProvenance provenance) noexcept;
/// Inverse of toString; returns false for an unknown name.
bool parseVertexProvenance(const std::string& name, VertexProvenance& provenance) noexcept;

/// The result of the inner loop at one vertex.
struct VertexEstimate {
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();  ///< Final G_hat(X_i). Unit: [N]
  /// Iterations the estimate took (0 for a vertex that was not measured).
  int iterations = 0;
  double seconds = 0.0;  ///< Servo time spent at the vertex, move excluded. Unit: [s]
  /// The motors' thermal load when the estimate was made (ThermalLoadObserver: the square of the
  /// force sent over the continuous rating, low-passed over the motors' time constant), which
  /// concludeThermalDrift takes the warming out by. Kept in memory only: 0 in a map read from a
  /// file, and for the vertices a resumed run restored (AutoCalibrator::restore), which are then
  /// taken as measured cold and never chosen to see the drift by.
  double thermal_load = 0.0;
  /// How the vertex ended.
  VertexOutcome outcome = VertexOutcome::kPending;
  /// Where the value comes from: measured, or filled from its neighbours.
  VertexProvenance provenance = VertexProvenance::kMeasured;
  std::vector<IterationRecord> history;  ///< One record per iteration, oldest first.
  /// Where the inner loop ran when not at the vertex itself: a vertex beyond the explored
  /// workspace's boundary is measured at a point just inside it (MeasurementPlan), and its value
  /// gravity_n is then solved from every measurement (fillUnreachableVertices); NaN when measured
  /// at the vertex, or not at all. Unit: [m]
  Eigen::Vector3d measured_at_m =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The estimate measured at measured_at_m (only when measuredOffVertex()). Unit: [N]
  Eigen::Vector3d measured_gravity_n = Eigen::Vector3d::Zero();
  /// True when the estimate was measured at measured_at_m, not at the vertex.
  bool measuredOffVertex() const noexcept { return measured_at_m.allFinite(); }
  /// Where the estimate was measured: measured_at_m, or `vertex_m`, the vertex's own position.
  /// Unit: [m]
  Eigen::Vector3d measuredAt_m(const Eigen::Vector3d& vertex_m) const noexcept {
    return measuredOffVertex() ? measured_at_m : vertex_m;
  }
  /// What was measured there: measured_gravity_n off the vertex (gravity_n is then solved from
  /// every measurement), gravity_n at it. Unit: [N]
  const Eigen::Vector3d& measuredGravity_n() const noexcept {
    return measuredOffVertex() ? measured_gravity_n : gravity_n;
  }
};

}  // namespace autograv
