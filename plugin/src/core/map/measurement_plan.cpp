#include "autograv/map/measurement_plan.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "autograv/error.h"

namespace autograv {

bool MeasurementPlan::offVertex(const WorkspaceGrid& grid, int index) const noexcept {
  const auto i = static_cast<std::size_t>(index);
  return i < measure.size() && measure[i] &&
         (points_m[i] - grid.vertexPosition(index)).norm() > 1e-9;
}

MeasurementPlan planMeasurements(const WorkspaceGrid& grid, const ExploredWorkspace& workspace,
                                 double margin_m) {
  const int count = grid.vertexCount();
  MeasurementPlan plan;
  plan.points_m.resize(static_cast<std::size_t>(count));
  plan.measure.assign(static_cast<std::size_t>(count), false);
  plan.workspace = workspace;
  for (int i = 0; i < count; ++i)
    plan.points_m[static_cast<std::size_t>(i)] = grid.vertexPosition(i);
  if (workspace.empty()) {
    plan.measure.assign(static_cast<std::size_t>(count), true);
    plan.at_vertex = count;
    return plan;
  }
  // Vertices inside first, then the others from the boundary outward, so that a point pulled in
  // never displaces a vertex measured where it is.
  std::vector<double> depth(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    depth[static_cast<std::size_t>(i)] = workspace.depth_m(grid.vertexPosition(i));
  }
  std::vector<int> order(static_cast<std::size_t>(count));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return depth[static_cast<std::size_t>(a)] > depth[static_cast<std::size_t>(b)];
  });
  const double min_spacing_m = grid.spacing_m().minCoeff();
  const double max_spacing_m = grid.maxSpacing_m();
  std::vector<Eigen::Vector3d> planned;
  for (int index : order) {
    const auto i = static_cast<std::size_t>(index);
    const Eigen::Vector3d vertex_m = grid.vertexPosition(index);
    if (depth[i] >= margin_m) {
      plan.measure[i] = true;
      planned.push_back(vertex_m);
      ++plan.at_vertex;
      continue;
    }
    const Eigen::Vector3d inside_m = workspace.pullInside(vertex_m, margin_m);
    const bool near_boundary = (inside_m - vertex_m).norm() <= max_spacing_m;
    const bool crowded = std::any_of(planned.begin(), planned.end(), [&](const Eigen::Vector3d& p) {
      return (p - inside_m).norm() < min_spacing_m / 3.0;
    });
    if (!near_boundary || crowded) {
      ++plan.skipped;
      continue;
    }
    plan.measure[i] = true;
    plan.points_m[i] = inside_m;
    planned.push_back(inside_m);
    ++plan.off_vertex;
  }
  return plan;
}

WorkspaceGrid gridAroundWorkspace(const ExploredWorkspace& workspace,
                                  const Eigen::Vector3i& resolution) {
  if (workspace.empty()) {
    throw Error("gridAroundWorkspace: the workspace is empty; explore it first");
  }
  constexpr int kDirections = 2000;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d high = Eigen::Vector3d::Constant(-1e300);
  for (const Eigen::Vector3d& u : ExploredWorkspace::probeDirections(kDirections)) {
    const Eigen::Vector3d point = workspace.center_m() + workspace.boundaryDistance_m(u) * u;
    low = low.cwiseMin(point);
    high = high.cwiseMax(point);
  }
  // Millimetre extents, so that maps and reports read cleanly.
  const Eigen::Vector3d size_m = ((high - low) * 1e3).array().round().max(1.0) * 1e-3;
  return WorkspaceGrid(0.5 * (low + high), size_m, resolution);
}

}  // namespace autograv
