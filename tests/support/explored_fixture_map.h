#pragma once

// A gravity map made the way a calibration on an explored workspace makes one, without running
// one: for the pictures and summaries of such maps (the viz and gl tests).

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/vertex_fill.h"

namespace autograv::testing {

/// How a fixture's workspace is explored: probes from `center_m` along `directions` rays stop
/// where `reachable` ends (to 0.5 mm), like WorkspaceExplorer's probe stops at the device's
/// stops.
struct ExploredFixtureSpec {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  int directions = 26;
  int resolution = 5;  ///< Vertices per axis of the grid fitted around the workspace.
  /// Relative size of the deterministic estimation error added to the truth.
  double error_fraction = 0.006;
  std::string model = "fixture:explored";
};

/// The probes' stops in `reachable` (see ExploredFixtureSpec). Throws autograv::Error when a ray
/// does not end within 1 m.
inline ExploredWorkspace exploreFixtureWorkspace(
    const std::function<bool(const Eigen::Vector3d&)>& reachable, const ExploredFixtureSpec& spec) {
  constexpr double kStep_m = 0.0005;
  std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(spec.directions);
  std::vector<double> radii_m;
  for (const Eigen::Vector3d& u : directions) {
    double reach_m = kStep_m;
    while (reachable(spec.center_m + (reach_m + kStep_m) * u)) {
      reach_m += kStep_m;
      if (reach_m > 1.0) throw Error("fixture: a probe ray never met a stop");
    }
    radii_m.push_back(reach_m);
  }
  return ExploredWorkspace(spec.center_m, std::move(directions), std::move(radii_m));
}

/// A map made the way a calibration on an explored workspace makes one, in milliseconds: the
/// workspace from exploreFixtureWorkspace, the grid fitted around it (gridAroundWorkspace), the
/// measurement plan (planMeasurements): vertices inside measured at the vertex, those within a
/// cell of the boundary measured just inside it, the rest solved from every measurement
/// (fillUnreachableVertices). Each measurement is the truth there plus a small deterministic
/// error, with a synthetic convergence history.
inline GravityMap makeExploredFixtureMap(
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& truth,
    const std::function<bool(const Eigen::Vector3d&)>& reachable,
    const ExploredFixtureSpec& spec = {}) {
  ExploredWorkspace workspace = exploreFixtureWorkspace(reachable, spec);
  const WorkspaceGrid grid =
      gridAroundWorkspace(workspace, Eigen::Vector3i::Constant(spec.resolution));
  const MeasurementPlan plan = planMeasurements(grid, workspace);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    const auto index = static_cast<std::size_t>(i);
    if (!plan.measure[index]) {
      v.outcome = VertexOutcome::kUnreachable;
      continue;
    }
    const Eigen::Vector3d& point_m = plan.points_m[index];
    const Eigen::Vector3d g = truth(point_m);
    const Eigen::Vector3d wobble(std::sin(1.7 * i), std::cos(2.3 * i), std::sin(0.9 * i + 1.0));
    v.gravity_n = g + spec.error_fraction * g.norm() * wobble;
    v.iterations = 4 + (i * 7) % 3;  // short histories keep the fixture file small
    v.seconds = 0.25 * v.iterations;
    v.outcome = VertexOutcome::kConverged;
    for (int j = 1; j <= v.iterations; ++j) {
      IterationRecord record;
      record.position_error_m = 0.008 * std::pow(0.45, j - 1);
      record.mass_estimate_kg = g.norm() / kStandardGravity * (1.0 - 0.35 * std::pow(0.5, j - 1));
      record.gravity_estimate_n = v.gravity_n * (1.0 - 0.35 * std::pow(0.5, j - 1));
      record.duration_s = 0.25;
      v.history.push_back(record);
    }
    if (plan.offVertex(grid, i)) {
      v.measured_at_m = point_m;
      v.measured_gravity_n = v.gravity_n;
    }
  }
  fillUnreachableVertices(grid, vertices);
  MapMetadata metadata;
  metadata.device_model = spec.model;
  metadata.created_utc = "2026-01-01T00:00:00Z";
  metadata.workspace = std::move(workspace);
  metadata.lookup_refinement = kDefaultLookupRefinement;
  metadata.field_model = kDefaultFieldModel;
  return GravityMap(grid, std::move(vertices), metadata);
}

}  // namespace autograv::testing
