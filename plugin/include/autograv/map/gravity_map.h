#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/explored_workspace.h"
#include "autograv/map/field_fit.h"
#include "autograv/map/measurement_review.h"
#include "autograv/map/thermal_drift.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/types/estimation_parameters.h"
#include "autograv/types/vertex_estimate.h"

namespace autograv {

/// How a map was made from the map of another unit of the same model (transferMap, `calibrate
/// --like`): the prior it started from and the correction the spot measurements fitted. A map
/// made by a whole calibration has none.
struct MapPrior {
  std::string source;         ///< The prior map as the user named it (a path). May be empty.
  std::string device_serial;  ///< The prior unit's serial number (empty when unknown).
  std::string created_utc;    ///< When the prior map was made (its MapMetadata::created_utc).
  /// The correction's model: "shift", "affine", "conservative" or "componentwise"
  /// (toString(CorrectionModel)).
  std::string correction_model;
  /// The correction added to the prior's value G_p at x: (gain - I) G_p(x) + offset_n, plus, for
  /// the two field models, the FieldFit (of that model) of `residuals_n` at `points_m`.
  Eigen::Matrix3d gain = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset_n = Eigen::Vector3d::Zero();  ///< Unit: [N]
  std::vector<Eigen::Vector3d> points_m;               ///< Where the fit measured. Unit: [m]
  /// What the field part fits at points_m (empty for "shift" and "affine"). Unit: [N]
  std::vector<Eigen::Vector3d> residuals_n;
  int check_points = 0;         ///< Measurements the correction did not use, to check it.
  double check_mean_rel = 0.0;  ///< Their mean |corrected map - measurement| / |G|.
  double check_max_rel = 0.0;   ///< Their largest.
  /// Largest difference between the prior's explored reach and this unit's, over the probed
  /// directions. Unit: [m]
  double workspace_difference_m = 0.0;
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
  /// The lookup's cells per grid cell along each axis. 1 with the thin plate: the paper's
  /// trilinear interpolation of the vertex values. Otherwise trilinear on a grid k times finer
  /// whose values are the field model's fit of every measurement, which follows a curved field
  /// between the vertices where the coarse cells cut its corners; the same cost per lookup.
  int lookup_refinement = 1;
  /// How the lookup grid's values are made from the measurements. kChoose fits every candidate
  /// and keeps the best by cross-validation (chooseFieldModel): the map's metadata() then says
  /// which, with every candidate's score, and a saved map keeps that choice. A map with fewer
  /// than FieldFit::kMinMeasurements or more than kMaxMeasurements measurements, with
  /// measurements that do not determine the fit, or whose padded lookup grid would pass
  /// kMaxLookupVertices, falls back to kThinPlate at a refinement of at most
  /// kThinPlateRefinement (GravityMap::fieldModel and lookupRefinement say what it uses).
  FieldModel field_model = FieldModel::kThinPlate;
  /// The curl weight of a kCorrected model's fit (FieldFit), in [0, FieldFit::kMaxCurlWeight]: 0
  /// asks for the weight to be chosen by cross-validation (bestCorrectedScore), which the map's
  /// metadata() then holds. The other models have their own.
  double curl_weight = 0.0;
  /// Every candidate's cross-validation score where the model was chosen (empty where it was
  /// given).
  std::vector<FieldModelScore> field_model_scores;
  /// The map of another unit this one was corrected from; empty for a whole calibration.
  std::optional<MapPrior> prior;
  /// The measurements that the others contradicted (judgeMeasurements), each measured again, and
  /// whether it was left out of the fit: empty when none stood out.
  std::vector<ReviewedMeasurement> reviewed_measurements;
  /// What the calibration saw of its motors warming, and the correction the decorator applies
  /// for it (thermalScale): all zero for a map made before schema 8, or without the check.
  ThermalDrift thermal_drift;
};

/// The lookup refinement of the maps that calibrations make (at most: lookupRefinementFor): six
/// lookup cells per grid cell follow the conservative fit to within a few hundredths of a
/// percent of its field-wide p99 (README, "Why the map is right near the stops").
inline constexpr int kDefaultLookupRefinement = 6;
/// The field model of the maps that calibrations make: chosen from the measurements.
inline constexpr FieldModel kDefaultFieldModel = FieldModel::kChoose;
/// Largest lookup refinement a map accepts.
inline constexpr int kMaxLookupRefinement = 8;
/// Most vertices of a fitted lookup grid (a 37 x 37 x 37 grid, 1.6 MB: a 5x5x5 grid at
/// refinement 6 with its cell of padding): each value is a sum over the measurements when the
/// map is built (0.1 s for a 5x5x5 map, 0.6 s for an 8x8x8 one).
inline constexpr long kMaxLookupVertices = 50653;

/// Most vertices of a refined thin-plate lookup grid a map accepts (a 31 x 31 x 31 grid: a 16x16x16
/// grid at refinement 2, the finest the tools ever wrote). Its values take a sparse solve that
/// grows fast with the grid: 0.3 s at 17^3, 3 s at 23^3, 9.5 s at 25^3, 40 s at 31^3.
inline constexpr long kMaxThinPlateLookupVertices = 29791;
/// Most vertices of the refined thin-plate lookup grids the tools write (lookupRefinementFor): a
/// 23 x 23 x 23 grid, about 3 s to build.
inline constexpr long kToolsThinPlateLookupVertices = 12167;

/// The lookup refinement of thin-plate maps: the most the tools ask for with the thin plate
/// (lookupRefinementFor), and the most a map that asks for a fitted model but falls back to the
/// thin plate reads (GravityMap::lookupRefinement); that of the maps before schema 4. The
/// thin plate's refined values take a sparse solve that grows fast with the refinement (a 5x5x5
/// grid: 0.03 s at 2, 0.35 s at 4, 9.5 s at 6).
inline constexpr int kThinPlateRefinement = 2;

/// `metadata` for a checkpoint: the paper's trilinear lookup, which costs nothing to build. A
/// checkpoint is read for its vertices and workspace (a resumed run saves its map with the
/// run's own metadata), and one is written after every vertex.
MapMetadata checkpointMetadata(MapMetadata metadata);

/// Vertices per axis of the lookup grid of a map over `grid`: `refinement` lookup cells per grid
/// cell, and for a fitted model (every one but kThinPlate) one grid cell more on every side.
Eigen::Vector3i lookupResolution(const WorkspaceGrid& grid, int refinement,
                                 FieldModel model) noexcept;

/// The largest refinement up to `wanted` whose fitted lookup grid over `grid` stays within
/// kMaxLookupVertices (1 at least): what the tools ask for, so that a fine grid gets a map too.
/// Where the map reads the thin plate (asked for, or a grid of more vertices than
/// FieldFit::kMaxMeasurements) at most kThinPlateRefinement, within
/// kToolsThinPlateLookupVertices: 2 up to a 12x12x12 grid, 1 from 13x13x13 on.
int lookupRefinementFor(const WorkspaceGrid& grid, int wanted,
                        FieldModel model = kDefaultFieldModel) noexcept;

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
  /// metadata().lookup_refinement > 1; of the field model's fit sampled on a lookup grid that
  /// reaches one grid cell beyond the box when fieldModel() is not kThinPlate) in the cell
  /// containing `position_m`; outside the lookup grid, its boundary cell's interpolant extended
  /// linearly for one lookup cell, and the value one cell out beyond that
  /// (detail::kExtrapolationCells). Unit: [N].
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
  /// The field model the lookup uses: metadata().field_model (the chosen one where it was
  /// kChoose), or kThinPlate where the measurements could not determine a fit. Never kChoose.
  FieldModel fieldModel() const noexcept { return field_model_; }
  /// The curl weight of the lookup's fit (0 conservative, 1 componentwise, the corrected model's
  /// own; 0 for the thin plate).
  double curlWeight() const noexcept { return curl_weight_; }
  /// The refinement the lookup uses: metadata().lookup_refinement, or at most
  /// kThinPlateRefinement where a fitted model fell back to the thin plate.
  int lookupRefinement() const noexcept { return lookup_refinement_; }
  /// True when every vertex has converged, or was found unreachable and filled from measured
  /// neighbours: the map has no holes.
  bool isComplete() const noexcept;

 private:
  WorkspaceGrid grid_;
  std::vector<VertexEstimate> vertices_;
  MapMetadata metadata_;
  FieldModel field_model_ = FieldModel::kThinPlate;
  double curl_weight_ = 0.0;
  int lookup_refinement_ = 1;

  /// The fit of the vertices' measurements in metadata_'s model, choosing it first where that is
  /// kChoose (and writing the choice into metadata_), or none where they cannot determine one.
  std::optional<FieldFit> fieldFit();
  /// Throws autograv::Error for a value that is not finite or beyond kMaxGravityEstimate_n.
  static void checkEstimate(const Eigen::Vector3d& gravity_n, std::size_t index,
                            const char* what = "vertex");

  // The lookup's view of the grid (refined by lookup_refinement_), computed once: no
  // division per query.
  Eigen::Vector3i lookup_resolution_;
  Eigen::Vector3d lookup_min_corner_m_;    ///< Unit: [m]
  Eigen::Vector3d inverse_spacing_per_m_;  ///< Per axis. Unit: [1/m]
  Eigen::Vector3d grid_low_m_;             ///< The calibration grid's box. Unit: [m]
  Eigen::Vector3d grid_high_m_;            ///< Unit: [m]
  /// The estimates again, zero-padded to four components in one aligned array: the lookup reads
  /// eight neighbours from it on whole SIMD packets. Unit: [N]
  std::vector<Eigen::Vector4d> packed_gravity_n_;
};

}  // namespace autograv
