#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/workspace_grid.h"

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
};

/// Where a map came from.
struct MapMetadata {
  std::string device_model;   ///< DeviceSpecifications::model_name at calibration time.
  std::string device_serial;  ///< Empty when unknown.
  std::string created_utc;    ///< ISO 8601, e.g. "2026-11-23T13:25:00Z".
  /// The estimation parameters of the calibration.
  EstimationParameters parameters;
  /// What the end-effector was found to reach before the grid run (empty for maps made before
  /// the exploration existed, or without it).
  ExploredWorkspace workspace;
  /// The lookup's cells per grid cell along each axis. 1: the paper's trilinear interpolation of
  /// the vertex values. k > 1: trilinear on a grid k times finer whose values are the thin-plate
  /// interpolant of every measurement (refinedVertexValues), which follows a curved field
  /// between the vertices where the coarse cells cut its corners; the same cost per lookup.
  int lookup_refinement = 1;
};

/// The lookup refinement of the maps that calibrations make: on the simulated devices it cuts the
/// field's 99th-percentile error between the vertices by a quarter at no extra device time.
inline constexpr int kDefaultLookupRefinement = 2;
/// Largest lookup refinement a map accepts.
inline constexpr int kMaxLookupRefinement = 8;
/// Most vertices of a refined lookup grid (a 33 x 33 x 33 grid): its values take one sparse solve
/// when the map is built.
inline constexpr long kMaxLookupVertices = 35937;

/// Largest magnitude of a vertex estimate's component that a map accepts. No device's gravity
/// comes near it; the bound keeps interpolation, ramps and the application's force plus the
/// compensation far from overflow in the servo path. Unit: [N]
inline constexpr double kMaxGravityEstimate_n = 1e9;

/// Apparent gravity estimated on the grid vertices, and its trilinear interpolation (the on-line
/// phase). Immutable once built, so one instance can be shared by a servo thread and others.
class GravityMap {
 public:
  /// Throws autograv::Error when vertices.size() != grid.vertexCount(), an estimate is not
  /// finite or has a component beyond kMaxGravityEstimate_n, or the lookup refinement lies
  /// outside 1..kMaxLookupRefinement or makes more than kMaxLookupVertices lookup vertices.
  /// Not real-time safe.
  GravityMap(WorkspaceGrid grid, std::vector<VertexEstimate> vertices, MapMetadata metadata);

  /// The grid of the map. Real-time safe.
  const WorkspaceGrid& grid() const noexcept { return grid_; }
  /// One estimate per grid vertex, by grid index. Real-time safe.
  const std::vector<VertexEstimate>& vertices() const noexcept { return vertices_; }
  /// Device, date and parameters of the calibration. Real-time safe.
  const MapMetadata& metadata() const noexcept { return metadata_; }

  /// Trilinear interpolation of the vertex estimates (on the refined lookup grid when
  /// metadata().lookup_refinement > 1) in the cell containing `position_m`; outside
  /// the grid, the boundary cell's interpolant extended linearly for one cell, and the value one
  /// cell out beyond that (detail::kExtrapolationCells). Unit: [N].
  /// Real-time safe: no allocation, no lock, no throw.
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m) const noexcept;

  /// The same, and whether `position_m` lies within the grid grown by `margin_m` on every side
  /// (false for a NaN coordinate): how the compensation tells a position it may trust the map
  /// at from one it should not. Units: [m], [N]. Real-time safe.
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m, double margin_m,
                            bool& inside) const noexcept;

  /// Vertices whose outcome is kConverged.
  int convergedCount() const noexcept;
  /// Vertices whose outcome is kUnreachable.
  int unreachableCount() const noexcept;
  /// Vertices whose value was filled from neighbours.
  int filledCount() const noexcept;
  /// True when every vertex has converged, or was found unreachable and filled from measured
  /// neighbours: the map has no holes.
  bool isComplete() const noexcept;

 private:
  WorkspaceGrid grid_;
  std::vector<VertexEstimate> vertices_;
  MapMetadata metadata_;
  // The lookup's view of the grid (refined by metadata.lookup_refinement), computed once: no
  // division per query.
  Eigen::Vector3i lookup_resolution_;
  Eigen::Vector3d min_corner_m_;
  Eigen::Vector3d inverse_spacing_per_m_;  ///< Per axis. Unit: [1/m]
  Eigen::Vector3d last_cell_;              ///< resolution - 1 per axis. Unit: [cells]
  /// The estimates again, zero-padded to four components in one aligned array: the lookup reads
  /// eight neighbours from it on whole SIMD packets. Unit: [N]
  std::vector<Eigen::Vector4d> packed_gravity_n_;
};

}  // namespace autograv
