#pragma once
// A map off by the same fraction everywhere: what `verify` must call FAIL.
#include <vector>

#include "autograv/map/gravity_map.h"

namespace autograv::testing {

/// `map` with every value it holds (at the vertices and where measured off them) times `factor`.
inline GravityMap scaledMap(const GravityMap& map, double factor) {
  std::vector<VertexEstimate> vertices = map.vertices();
  for (VertexEstimate& vertex : vertices) {
    vertex.gravity_n *= factor;
    vertex.measured_gravity_n *= factor;
  }
  return GravityMap(map.grid(), vertices, map.metadata());
}

}  // namespace autograv::testing
