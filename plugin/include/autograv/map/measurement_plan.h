#pragma once

#include <vector>

#include <Eigen/Core>

#include "autograv/map/explored_workspace.h"
#include "autograv/map/workspace_grid.h"

namespace autograv {

/// Where the calibration measures each grid vertex: at the vertex when it lies inside the explored
/// workspace, at a point just inside the boundary when the vertex lies beyond it but within a
/// cell of it (so that every cell the boundary cuts rests on a measurement next to the stops), or
/// nowhere when it lies further out (its value is then solved from the others). No point lies
/// outside the explored workspace.
struct MeasurementPlan {
  /// Per vertex: where the inner loop runs (meaningful only where `measure` is true). Unit: [m]
  std::vector<Eigen::Vector3d> points_m;
  /// Per vertex: whether it is measured at all.
  std::vector<bool> measure;
  /// The workspace the points were planned in (empty: none was explored), which bounds how far
  /// a move into a point may overshoot it.
  ExploredWorkspace workspace;
  int at_vertex = 0;   ///< Vertices measured where they are.
  int off_vertex = 0;  ///< Vertices measured at a point pulled inside the boundary.
  int skipped = 0;     ///< Vertices beyond reach, solved from the others.

  /// True when vertex `index` is measured off its position.
  bool offVertex(const WorkspaceGrid& grid, int index) const noexcept;
};

/// How far inside the explored boundary measurement points stay. The probe recorded the boundary
/// where a stop held it, pressed into its rubber (about 2 mm on sim:falcon's travel stops), so a
/// point this close may still meet a stop during its hold: the calibrator sees that contact from
/// the hold's own data and moves the point back (AutoCalibrator::kStopRetreat_m). Unit: [m]
inline constexpr double kBoundaryMargin_m = 0.0015;

/// Plans the measurements of `grid` in `workspace` (every vertex at itself when the workspace is
/// empty). Points pulled inside that would fall within a third of a cell of a point already
/// planned are dropped (that vertex is solved instead). Not real-time safe. Unit: [m]
MeasurementPlan planMeasurements(const WorkspaceGrid& grid, const ExploredWorkspace& workspace,
                                 double margin_m = kBoundaryMargin_m);

/// The box around everything `workspace` reaches (its bounding box, found over a dense set of
/// directions), with `resolution` vertices per axis: the default calibration grid, so that the
/// map is made of measurements wherever the hand can be. Throws autograv::Error for an empty
/// workspace. Not real-time safe.
WorkspaceGrid gridAroundWorkspace(const ExploredWorkspace& workspace,
                                  const Eigen::Vector3i& resolution);

}  // namespace autograv
