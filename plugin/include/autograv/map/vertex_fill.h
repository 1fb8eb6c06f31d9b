#pragma once

#include <vector>

#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"

namespace autograv {

/// Gives every vertex whose outcome is kUnreachable, and every converged vertex that was measured
/// off its position (VertexEstimate::measuredOffVertex: a point just inside the explored
/// workspace), a value solved from all measurements, so that the map has no holes and its
/// interpolant reproduces the measurements made off the vertices too; marks them
/// VertexProvenance::kFilled. Vertices measured at their position keep their values exactly. The
/// solved values minimise the squared misfit at the off-vertex measurements plus a
/// discrete thin-plate energy (squared second differences along each axis and squared mixed
/// differences across each cell face, scaled by the cell edges) with the converged values held
/// fixed: a field that is affine in x, y and z is reproduced at the filled vertices (to about
/// 1e-9 of its magnitude: a vanishing membrane term keeps the system regular when the measured
/// vertices are all coplanar). Vertices with any other outcome keep their values.
/// Returns the number of vertices filled; 0 when there is nothing to fill or no converged vertex
/// to fill from (the unreachable vertices then keep their provenance).
/// Throws autograv::Error when vertices.size() != grid.vertexCount(). Not real-time safe.
int fillUnreachableVertices(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices);

/// The values of the grid with `factor` times as many cells per axis over the same box, solved
/// from every measurement in `vertices` (fillUnreachableVertices over the finer grid): the
/// vertices of `grid` keep their values at their places in the finer grid, the vertices between
/// them follow the thin-plate interpolant of the measurements. Index order as WorkspaceGrid's.
/// Throws autograv::Error for a factor below 1 or more than 64 vertices per axis.
/// Not real-time safe.
std::vector<Eigen::Vector3d> refinedVertexValues(const WorkspaceGrid& grid,
                                                 const std::vector<VertexEstimate>& vertices,
                                                 int factor);

}  // namespace autograv
