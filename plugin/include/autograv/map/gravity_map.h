#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/explored_workspace.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/types/estimation_parameters.h"
#include "autograv/types/vertex_estimate.h"

namespace autograv {

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
