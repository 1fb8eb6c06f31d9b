#pragma once
// A map off by the same fraction everywhere (what `verify` must call FAIL), and one off by a
// random fraction at every value (what no smooth correction explains).
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "autograv/maintenance/retare.h"
#include "autograv/map/gravity_map.h"

namespace autograv::testing {

/// `map` with every value it holds (at the vertices and where measured off them) times `factor`.
using autograv::scaledMap;

/// `map` with every value off by its own random relative error, `spread` in magnitude on
/// average (the same draw where a vertex was measured off its position), drawn from `seed`.
inline GravityMap scrambledMap(const GravityMap& map, double spread, std::uint32_t seed) {
  std::vector<VertexEstimate> vertices = map.vertices();
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, spread / std::sqrt(3.0));
  for (VertexEstimate& vertex : vertices) {
    const double size_n = vertex.gravity_n.norm();
    const Eigen::Vector3d noise_n(normal(random), normal(random), normal(random));
    vertex.gravity_n += size_n * noise_n;
    if (vertex.measuredOffVertex()) vertex.measured_gravity_n += size_n * noise_n;
  }
  return GravityMap(map.grid(), vertices, map.metadata());
}

}  // namespace autograv::testing
