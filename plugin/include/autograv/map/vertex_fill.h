#pragma once

#include <vector>

#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"

namespace autograv {

/// Gives every vertex whose outcome is kUnreachable a value from the converged vertices, so that
/// the map has no holes, and marks it VertexProvenance::kFilled. The filled values minimise a
/// discrete thin-plate energy (squared second differences along each axis and squared mixed
/// differences across each cell face, scaled by the cell edges) with the converged values held
/// fixed: a field that is affine in x, y and z is reproduced at the filled vertices (to about
/// 1e-9 of its magnitude: a vanishing membrane term keeps the system regular when the measured
/// vertices are all coplanar). Vertices with any other outcome keep their values.
/// Returns the number of vertices filled; 0 when there is nothing to fill or no converged vertex
/// to fill from (the unreachable vertices then keep their provenance).
/// Throws autograv::Error when vertices.size() != grid.vertexCount(). Not real-time safe.
int fillUnreachableVertices(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices);

}  // namespace autograv
