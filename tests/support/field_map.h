#pragma once

// Gravity maps for the decorator's tests: a known field sampled at the vertices of a grid, every
// vertex converged, so that what the decorator sends can be checked against the field.

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"

namespace autograv::testing {

/// A map on `grid` holding field(X) at every vertex X, made for the device model
/// metadata.device_model.
template <typename Field>
std::shared_ptr<const GravityMap> fieldMap(const WorkspaceGrid& grid, Field field,
                                           MapMetadata metadata) {
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n = field(grid.vertexPosition(i));
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
  }
  return std::make_shared<const GravityMap>(grid, std::move(vertices), std::move(metadata));
}

/// A map on `grid` holding `gravity_n` everywhere, made for the device model `model`.
inline std::shared_ptr<const GravityMap> uniformFieldMap(const WorkspaceGrid& grid,
                                                         const Eigen::Vector3d& gravity_n,
                                                         const std::string& model) {
  MapMetadata metadata;
  metadata.device_model = model;
  return fieldMap(
      grid, [&gravity_n](const Eigen::Vector3d&) { return gravity_n; }, std::move(metadata));
}

}  // namespace autograv::testing
